package feelmysign.simplify;

/**
 * A straight piece of a path, in grid units, and when the simplifier let it go.
 *
 * <p>{@code dropped} is null for a stroke to send, else the reason it is too short or too brief
 * to feel ({@link #NOT_ENOUGH_DISTANCE}, {@link #NOT_ENOUGH_DURATION}). Sent and dropped segments
 * of a path together join end to start, so a dropped one leaves a gap no longer than itself.
 */
public record Segment(
    double startX,
    double startY,
    double endX,
    double endY,
    double startMs,
    double endMs,
    double emittedAtMs,
    String dropped,
    int merged,
    double playMs) {

  /**
   * A segment played as drawn ({@code playMs} NaN): the window simplifier gives a stroke drawn
   * briefer than the sleeve's floor the floor as {@code playMs} instead.
   */
  public Segment(
      double startX,
      double startY,
      double endX,
      double endY,
      double startMs,
      double endMs,
      double emittedAtMs,
      String dropped,
      int merged) {
    this(startX, startY, endX, endY, startMs, endMs, emittedAtMs, dropped, merged, Double.NaN);
  }

  /** A segment into which no piece was merged. */
  public Segment(
      double startX,
      double startY,
      double endX,
      double endY,
      double startMs,
      double endMs,
      double emittedAtMs,
      String dropped) {
    this(startX, startY, endX, endY, startMs, endMs, emittedAtMs, dropped, 0);
  }

  /** The paper's NotEnoughDistanceException. */
  public static final String NOT_ENOUGH_DISTANCE = "not_enough_distance";
  /** The paper's NotEnoughDurationException. */
  public static final String NOT_ENOUGH_DURATION = "not_enough_duration";

  /**
   * How long the sleeve is to play it: as drawn ({@link #drawnMs()}), or the floor for a stroke
   * of the window simplifier drawn briefer than the sleeve's floor.
   */
  public double durationMs() {
    return Double.isNaN(playMs) ? endMs - startMs : playMs;
  }

  /** How long the piece took to draw. */
  public double drawnMs() {
    return endMs - startMs;
  }

  public double length() {
    double dx = endX - startX;
    double dy = endY - startY;
    return Math.sqrt(dx * dx + dy * dy);
  }

  /** Whether this is a stroke to send (not dropped). */
  public boolean sent() {
    return dropped == null;
  }

  /**
   * This piece, finished: sent, or dropped as too short (first) or too brief to feel. Length is
   * tested first, as the paper does: a tap is "not enough distance".
   */
  Segment checked(double minLength, double minDurationMs) {
    String reason = null;
    if (length() < minLength) {
      reason = NOT_ENOUGH_DISTANCE;
    } else if (drawnMs() < minDurationMs) {
      reason = NOT_ENOUGH_DURATION;
    }
    return reason == null
        ? this
        : new Segment(startX, startY, endX, endY, startMs, endMs, emittedAtMs, reason, merged);
  }
}
