package feelmysign.json;


import java.math.BigInteger;
import java.util.List;
import java.util.Map;

/** Python's {@code repr()} of the values a parameter can be given, for the same messages. */
public final class PyRepr {
  private PyRepr() {}

  /** Python's {@code type(value).__name__} of a JSON-like value: "int", "str", "dict"... */
  public static String typeName(Object value) {
    if (value == null) {
      return "NoneType";
    }
    if (value instanceof Long || value instanceof Integer || value instanceof BigInteger) {
      return "int";
    }
    if (value instanceof Double || value instanceof Float) {
      return "float";
    }
    if (value instanceof Boolean) {
      return "bool";
    }
    if (value instanceof String) {
      return "str";
    }
    if (value instanceof List) {
      return "list";
    }
    return value instanceof Map ? "dict" : value.getClass().getSimpleName();
  }

  /** Python's repr of a JSON-like value: True, 1.0, 'text', [1, 2], {'a': None}. */
  public static String of(Object value) {
    if (value == null) {
      return "None";
    }
    if (value instanceof Boolean b) {
      return b ? "True" : "False";
    }
    if (value instanceof Double d) {
      return Numbers.pythonRepr(d);
    }
    if (value instanceof Float f) {
      return Numbers.pythonRepr(f.doubleValue());
    }
    if (value instanceof Long || value instanceof Integer || value instanceof BigInteger
        || value instanceof Short || value instanceof Byte) {
      return value.toString();
    }
    if (value instanceof String s) {
      return string(s);
    }
    if (value instanceof List<?> list) {
      StringBuilder out = new StringBuilder("[");
      for (int i = 0; i < list.size(); i++) {
        out.append(i > 0 ? ", " : "").append(of(list.get(i)));
      }
      return out.append(']').toString();
    }
    if (value instanceof Map<?, ?> map) {
      StringBuilder out = new StringBuilder("{");
      boolean first = true;
      for (Map.Entry<?, ?> entry : map.entrySet()) {
        out.append(first ? "" : ", ").append(of(entry.getKey())).append(": ").append(of(entry.getValue()));
        first = false;
      }
      return out.append('}').toString();
    }
    return String.valueOf(value);
  }

  /** A str's repr: single quotes unless the text has one and no double quote. */
  private static String string(String s) {
    char quote = s.indexOf('\'') >= 0 && s.indexOf('"') < 0 ? '"' : '\'';
    StringBuilder out = new StringBuilder().append(quote);
    s.codePoints()
        .forEach(
            c -> {
              if (c == quote || c == '\\') {
                out.append('\\').appendCodePoint(c);
              } else if (c == '\n') {
                out.append("\\n");
              } else if (c == '\r') {
                out.append("\\r");
              } else if (c == '\t') {
                out.append("\\t");
              } else if (c < 0x20 || c == 0x7f) {
                out.append(String.format("\\x%02x", c));
              } else if (!printable(c)) {
                out.append(
                    c <= 0xff
                        ? String.format("\\x%02x", c)
                        : c <= 0xffff ? String.format("\\u%04x", c) : String.format("\\U%08x", c));
              } else {
                out.appendCodePoint(c);
              }
            });
    return out.append(quote).toString();
  }

  private static boolean printable(int c) {
    int type = Character.getType(c);
    return c == ' '
        || !(type == Character.CONTROL
            || type == Character.FORMAT
            || type == Character.SURROGATE
            || type == Character.PRIVATE_USE
            || type == Character.UNASSIGNED
            || type == Character.LINE_SEPARATOR
            || type == Character.PARAGRAPH_SEPARATOR
            || type == Character.SPACE_SEPARATOR);
  }
}
