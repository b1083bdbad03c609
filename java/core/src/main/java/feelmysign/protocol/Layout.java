package feelmysign.protocol;

/**
 * The limits of a sleeve that a stroke is validated against: its grid (rows x columns of
 * actuators) and the longest stroke it plays. The rest of a sleeve's layout (wiring, safety
 * caps) stays with the sleeve.
 */
public record Layout(int rows, int columns, double maxStrokeDurationMs) {
  /** The paper's sleeve: 3 rows x 4 columns, strokes of at most 10 s. */
  public static final Layout PAPER = new Layout(3, 4, 10_000.0);

  public Layout {
    if (rows < 1 || rows > 64 || columns < 1 || columns > 64) {
      throw new IllegalArgumentException(
          "a sleeve grid is 1 to 64 rows by 1 to 64 columns, not " + rows + " x " + columns);
    }
    if (!(maxStrokeDurationMs > 0) || Double.isInfinite(maxStrokeDurationMs)) {
      throw new IllegalArgumentException(
          "maxStrokeDurationMs must be a finite number above 0, not " + maxStrokeDurationMs);
    }
  }
}
