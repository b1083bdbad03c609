package feelmysign.protocol;

/**
 * A stroke no sleeve would accept, refused before it reaches the wire. {@code reason} is one of
 * the protocol's reason codes ({@link Reasons}); the message says what to change.
 */
public final class StrokeException extends IllegalArgumentException {
  private static final long serialVersionUID = 1L;

  private final String reason;

  public StrokeException(String reason, String message) {
    super(message);
    this.reason = reason;
  }

  public String reason() {
    return reason;
  }
}
