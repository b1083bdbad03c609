package feelmysign.json;

import java.math.BigInteger;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * A JSON reader that reads exactly what the Python reference's {@code json.loads} reads, and
 * fails where and how it fails, with the same messages and positions.
 *
 * <p>The protocol's refusals quote Python's decoder ("Expecting ',' delimiter at line 1, column
 * 8"), so every port must find the same first error at the same place: this is a port of
 * CPython's C scanner ({@code Modules/_json.c}), not a general JSON library. Values are
 * {@link Map} (insertion order, a repeated key keeps its first place and its last value),
 * {@link List}, {@link String}, {@link Long} or {@link BigInteger} (integers, as Python keeps them
 * apart from floats), {@link Double}, {@link Boolean} and {@code null}. NaN and Infinity are
 * refused through {@link NonFiniteLiteralException}, as the reference's {@code parse_constant}.
 * Positions count Unicode code points, as Python's string indices do.
 */
public final class PyJson {
  /** Deeper nesting than this is refused, as Python's stack limit refuses it. */
  public static final int MAX_DEPTH = 900;

  private final String text;
  private final int length;
  private int depth;

  private PyJson(String text) {
    this.text = text;
    this.length = text.length();
  }

  /** Python's {@code json.loads(text)} with a {@code parse_constant} that refuses NaN/Infinity. */
  public static Object loads(String text) {
    if (text.startsWith("\ufeff")) {
      throw new JsonDecodeException(
          "Unexpected UTF-8 BOM (decode using utf-8-sig)", text, 0);
    }
    PyJson reader = new PyJson(text);
    int start = reader.skipWhitespace(0);
    int[] end = new int[1];
    Object value = reader.scanOrExpect(start, end);
    int after = reader.skipWhitespace(end[0]);
    if (after != text.length()) {
      throw new JsonDecodeException("Extra data", text, after);
    }
    return value;
  }

  private int skipWhitespace(int index) {
    while (index < length && isWhitespace(text.charAt(index))) {
      index++;
    }
    return index;
  }

  private static boolean isWhitespace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
  }

  /** A value at {@code index}, or "Expecting value" where none starts (Python's StopIteration). */
  private Object scanOrExpect(int index, int[] end) {
    Object value = scan(index, end);
    if (value == NO_VALUE) {
      throw new JsonDecodeException("Expecting value", text, end[0]);
    }
    return value;
  }

  private static final Object NO_VALUE = new Object();

  /** CPython's scan_once_unicode: the value at index, or NO_VALUE with end[0] = where it failed. */
  private Object scan(int index, int[] end) {
    if (index >= length) {
      end[0] = index;
      return NO_VALUE;
    }
    char c = text.charAt(index);
    switch (c) {
      case '"':
        return scanString(index + 1, end);
      case '{':
        return nested(() -> scanObject(index + 1, end));
      case '[':
        return nested(() -> scanArray(index + 1, end));
      case 'n':
        if (text.startsWith("null", index)) {
          end[0] = index + 4;
          return null;
        }
        break;
      case 't':
        if (text.startsWith("true", index)) {
          end[0] = index + 4;
          return Boolean.TRUE;
        }
        break;
      case 'f':
        if (text.startsWith("false", index)) {
          end[0] = index + 5;
          return Boolean.FALSE;
        }
        break;
      case 'N':
        if (text.startsWith("NaN", index)) {
          throw new NonFiniteLiteralException("NaN");
        }
        break;
      case 'I':
        if (text.startsWith("Infinity", index)) {
          throw new NonFiniteLiteralException("Infinity");
        }
        break;
      case '-':
        if (text.startsWith("-Infinity", index)) {
          throw new NonFiniteLiteralException("-Infinity");
        }
        break;
      default:
        break;
    }
    return scanNumber(index, end);
  }

  private interface Scan {
    Object run();
  }

  private Object nested(Scan scan) {
    if (++depth > MAX_DEPTH) {
      throw new JsonDecodeException("nested too deeply", text, -1);
    }
    try {
      return scan.run();
    } finally {
      depth--;
    }
  }

  private static boolean isDigit(char c) {
    return c >= '0' && c <= '9';
  }

  /** CPython's _match_number_unicode, its backtracking on a bare exponent included. */
  private Object scanNumber(int start, int[] end) {
    int endIndex = length - 1;
    int index = start;
    if (text.charAt(index) == '-') {
      index++;
      if (index > endIndex) {
        end[0] = start;
        return NO_VALUE;
      }
    }
    char first = text.charAt(index);
    if (first >= '1' && first <= '9') {
      index++;
      while (index <= endIndex && isDigit(text.charAt(index))) {
        index++;
      }
    } else if (first == '0') {
      index++;
    } else {
      end[0] = start;
      return NO_VALUE;
    }
    boolean isFloat = false;
    if (index < endIndex && text.charAt(index) == '.' && isDigit(text.charAt(index + 1))) {
      isFloat = true;
      index += 2;
      while (index <= endIndex && isDigit(text.charAt(index))) {
        index++;
      }
    }
    if (index < endIndex && (text.charAt(index) == 'e' || text.charAt(index) == 'E')) {
      int exponentStart = index;
      index++;
      if (index < endIndex && (text.charAt(index) == '-' || text.charAt(index) == '+')) {
        index++;
      }
      while (index <= endIndex && isDigit(text.charAt(index))) {
        index++;
      }
      if (isDigit(text.charAt(index - 1))) {
        isFloat = true;
      } else {
        index = exponentStart;
      }
    }
    String number = text.substring(start, index);
    end[0] = index;
    if (isFloat) {
      return Double.parseDouble(number);
    }
    if (number.length() <= 18) {
      return Long.parseLong(number);
    }
    BigInteger big = new BigInteger(number);
    return big.bitLength() < 64 ? (Object) big.longValue() : big;
  }

  /** CPython's scanstring_unicode (strict): {@code begin} is just after the opening quote. */
  private String scanString(int begin, int[] endOut) {
    int quote = begin - 1;
    StringBuilder out = new StringBuilder();
    int end = begin;
    while (true) {
      int next = end;
      char c = 0;
      for (; next < length; next++) {
        c = text.charAt(next);
        if (c == '"' || c == '\\') {
          break;
        }
        if (c <= 0x1f) {
          throw new JsonDecodeException("Invalid control character at", text, next);
        }
      }
      if (next >= length) {
        throw new JsonDecodeException("Unterminated string starting at", text, quote);
      }
      out.append(text, end, next);
      if (c == '"') {
        endOut[0] = next + 1;
        return out.toString();
      }
      next++; // the backslash
      if (next == length) {
        throw new JsonDecodeException("Unterminated string starting at", text, quote);
      }
      c = text.charAt(next);
      if (c != 'u') {
        end = next + 1;
        char decoded;
        switch (c) {
          case '"':
          case '\\':
          case '/':
            decoded = c;
            break;
          case 'b':
            decoded = '\b';
            break;
          case 'f':
            decoded = '\f';
            break;
          case 'n':
            decoded = '\n';
            break;
          case 'r':
            decoded = '\r';
            break;
          case 't':
            decoded = '\t';
            break;
          default:
            throw new JsonDecodeException("Invalid \\escape", text, end - 2);
        }
        out.append(decoded);
      } else {
        next++;
        end = next + 4;
        if (end >= length) {
          throw new JsonDecodeException("Invalid \\uXXXX escape", text, next - 1);
        }
        int unit = hex4(next, end);
        next = end;
        if (Character.isHighSurrogate((char) unit)
            && end + 6 < length
            && text.charAt(next) == '\\'
            && text.charAt(next + 1) == 'u') {
          int low = hex4(next + 2, end + 6);
          if (Character.isLowSurrogate((char) low)) {
            out.append((char) unit).append((char) low);
            end += 6;
            continue;
          }
        }
        out.append((char) unit);
      }
    }
  }

  private int hex4(int from, int end) {
    int value = 0;
    for (int i = from; i < end; i++) {
      int digit = Character.digit(text.charAt(i), 16);
      if (digit < 0 || text.charAt(i) > 'f') {
        throw new JsonDecodeException("Invalid \\uXXXX escape", text, end - 5);
      }
      value = (value << 4) | digit;
    }
    return value;
  }

  /** CPython's scanner_parse_object: {@code index} is just after the '{'. */
  private Object scanObject(int index, int[] end) {
    Map<String, Object> object = new LinkedHashMap<>();
    int endIndex = length - 1;
    index = skipWhitespace(index);
    if (index > endIndex || text.charAt(index) != '}') {
      while (true) {
        if (index > endIndex || text.charAt(index) != '"') {
          throw new JsonDecodeException(
              "Expecting property name enclosed in double quotes", text, index);
        }
        int[] next = new int[1];
        String key = scanString(index + 1, next);
        index = skipWhitespace(next[0]);
        if (index > endIndex || text.charAt(index) != ':') {
          throw new JsonDecodeException("Expecting ':' delimiter", text, index);
        }
        index = skipWhitespace(index + 1);
        Object value = scan(index, next);
        if (value == NO_VALUE) {
          end[0] = next[0];
          return NO_VALUE;
        }
        object.put(key, value);
        index = skipWhitespace(next[0]);
        if (index <= endIndex && text.charAt(index) == '}') {
          break;
        }
        if (index > endIndex || text.charAt(index) != ',') {
          throw new JsonDecodeException("Expecting ',' delimiter", text, index);
        }
        index = skipWhitespace(index + 1);
      }
    }
    end[0] = index + 1;
    return object;
  }

  /** CPython's scanner_parse_array: {@code index} is just after the '['. */
  private Object scanArray(int index, int[] end) {
    List<Object> array = new ArrayList<>();
    int endIndex = length - 1;
    index = skipWhitespace(index);
    if (index > endIndex || text.charAt(index) != ']') {
      while (true) {
        int[] next = new int[1];
        Object value = scan(index, next);
        if (value == NO_VALUE) {
          end[0] = next[0];
          return NO_VALUE;
        }
        array.add(value);
        index = skipWhitespace(next[0]);
        if (index <= endIndex && text.charAt(index) == ']') {
          break;
        }
        if (index > endIndex || text.charAt(index) != ',') {
          throw new JsonDecodeException("Expecting ',' delimiter", text, index);
        }
        index = skipWhitespace(index + 1);
      }
    }
    end[0] = index + 1;
    return array;
  }
}
