package feelmysign.json;

import java.math.BigInteger;
import java.util.List;
import java.util.Map;

/**
 * Python's {@code json.dumps(value)} (separators ", " and ": "), with or without
 * {@code ensure_ascii}: what the reference prints and quotes in its messages, to the byte.
 * Values as {@link PyJson} reads them; a float is a {@link Double} (written "1.0"), an integer a
 * {@link Long}, {@link Integer} or {@link BigInteger} (written "1").
 */
public final class PyDumps {
  private PyDumps() {}

  /** {@code json.dumps(value)}: non-ASCII written as \\uXXXX escapes. */
  public static String dumps(Object value) {
    StringBuilder out = new StringBuilder();
    write(out, value, true);
    return out.toString();
  }

  /** {@code json.dumps(value, ensure_ascii=False)}. */
  public static String dumpsUnicode(Object value) {
    StringBuilder out = new StringBuilder();
    write(out, value, false);
    return out.toString();
  }

  private static void write(StringBuilder out, Object value, boolean ascii) {
    if (value == null) {
      out.append("null");
    } else if (value instanceof Boolean b) {
      out.append(b ? "true" : "false");
    } else if (value instanceof String s) {
      string(out, s, ascii);
    } else if (value instanceof Double d) {
      out.append(Numbers.pythonJson(d));
    } else if (value instanceof Float f) {
      out.append(Numbers.pythonJson(f.doubleValue()));
    } else if (value instanceof Long || value instanceof Integer || value instanceof BigInteger) {
      out.append(value.toString());
    } else if (value instanceof Map<?, ?> map) {
      out.append('{');
      boolean first = true;
      for (Map.Entry<?, ?> entry : map.entrySet()) {
        if (!first) {
          out.append(", ");
        }
        first = false;
        string(out, String.valueOf(entry.getKey()), ascii);
        out.append(": ");
        write(out, entry.getValue(), ascii);
      }
      out.append('}');
    } else if (value instanceof List<?> list) {
      out.append('[');
      for (int i = 0; i < list.size(); i++) {
        if (i > 0) {
          out.append(", ");
        }
        write(out, list.get(i), ascii);
      }
      out.append(']');
    } else if (value instanceof double[] pair) {
      out.append('[');
      for (int i = 0; i < pair.length; i++) {
        if (i > 0) {
          out.append(", ");
        }
        out.append(Numbers.pythonJson(pair[i]));
      }
      out.append(']');
    } else {
      throw new IllegalArgumentException("not a JSON value: " + value.getClass().getName());
    }
  }

  private static void string(StringBuilder out, String s, boolean ascii) {
    out.append('"');
    for (int i = 0; i < s.length(); i++) {
      char c = s.charAt(i);
      switch (c) {
        case '"' -> out.append("\\\"");
        case '\\' -> out.append("\\\\");
        case '\n' -> out.append("\\n");
        case '\r' -> out.append("\\r");
        case '\t' -> out.append("\\t");
        case '\b' -> out.append("\\b");
        case '\f' -> out.append("\\f");
        default -> {
          if (c < 0x20 || (ascii && c > 0x7e)) {
            // Python's escapes are lower-case hex; non-BMP text is already two UTF-16 units.
            out.append(String.format("\\u%04x", (int) c));
          } else {
            out.append(c);
          }
        }
      }
    }
    out.append('"');
  }
}
