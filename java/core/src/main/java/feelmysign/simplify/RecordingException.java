package feelmysign.simplify;

/** A recording that cannot be read; says where and what is wrong, as the reference does. */
public final class RecordingException extends IllegalArgumentException {
  private static final long serialVersionUID = 1L;

  public RecordingException(String message) {
    super(message);
  }
}
