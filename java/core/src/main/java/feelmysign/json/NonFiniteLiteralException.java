package feelmysign.json;

/** NaN, Infinity or -Infinity in JSON text: Python's json reads them, JSON itself has none. */
public final class NonFiniteLiteralException extends IllegalArgumentException {
  private static final long serialVersionUID = 1L;

  private final String literal;

  NonFiniteLiteralException(String literal) {
    super(literal);
    this.literal = literal;
  }

  /** The literal as written: "NaN", "Infinity" or "-Infinity". */
  public String literal() {
    return literal;
  }
}
