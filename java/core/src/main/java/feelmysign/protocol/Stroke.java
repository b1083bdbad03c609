package feelmysign.protocol;

/**
 * A straight stroke from start to end, as the sleeve receives it.
 *
 * <p>Points are in grid units: x is the column index (0..columns-1), y the row index
 * (0..rows-1); actuators sit at integer coordinates. The optional fields are null when absent:
 * {@code intensity} null means the sleeve's default; {@code drawing} and {@code seq} let the
 * sleeve order and chain the strokes of one drawing; {@code sentAtMs} is the sender's wall clock
 * (ms since 1970-01-01 UTC).
 */
public record Stroke(
    double startX,
    double startY,
    double endX,
    double endY,
    double durationMs,
    Double intensity,
    String drawing,
    Long seq,
    Double sentAtMs) {

  /** A stroke without the optional fields. */
  public Stroke(double startX, double startY, double endX, double endY, double durationMs) {
    this(startX, startY, endX, endY, durationMs, null, null, null, null);
  }

  /** Length in grid units. */
  public double length() {
    return Math.hypot(endX - startX, endY - startY);
  }

  /** This stroke as one of a drawing: its id, its place in it and when it is sent. */
  public Stroke inDrawing(String drawingId, long sequence, double sentAt) {
    return new Stroke(startX, startY, endX, endY, durationMs, intensity, drawingId, sequence, sentAt);
  }

  /** This stroke stamped with the sender's clock (ms since 1970-01-01 UTC; null: none). */
  public Stroke withSentAt(Double sentAt) {
    return new Stroke(startX, startY, endX, endY, durationMs, intensity, drawing, seq, sentAt);
  }

  /** This stroke at an intensity from 0 to 1 (null: the sleeve's default). */
  public Stroke withIntensity(Double value) {
    return new Stroke(startX, startY, endX, endY, durationMs, value, drawing, seq, sentAtMs);
  }
}
