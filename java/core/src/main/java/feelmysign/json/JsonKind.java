package feelmysign.json;

/** What a JSON value is, in JSON's words, for error messages (Python's protocol.json_kind). */
public final class JsonKind {
  private JsonKind() {}

  /** "null", "an object", "an array", "a string", "a boolean" or "a number". */
  public static String of(Object value) {
    return switch (PyRepr.typeName(value)) {
      case "NoneType" -> "null";
      case "dict" -> "an object";
      case "list" -> "an array";
      case "str" -> "a string";
      case "bool" -> "a boolean";
      default -> "a number";
    };
  }
}
