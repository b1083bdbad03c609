package feelmysign.protocol;

/** What {@link Protocol#parse} makes of a payload: {@link Accepted} or {@link Rejected}. */
public sealed interface ParseResult permits ParseResult.Accepted, ParseResult.Rejected {

  /** A payload the sleeve would play: the stroke (clamped into the grid) and its format. */
  record Accepted(Stroke stroke, WireFormat format) implements ParseResult {}

  /**
   * A payload the sleeve refuses: a stable {@code reason} code (see {@link Reasons}), a sentence
   * a person can act on, and the stroke field at fault ({@code start}, {@code duration_ms}...)
   * when there is one (else null).
   */
  record Rejected(String reason, String message, String field) implements ParseResult {}
}
