package feelmysign.json;

import java.math.BigDecimal;
import java.math.MathContext;
import java.math.RoundingMode;

/**
 * Doubles written as the other ports write them, to the byte: Python's {@code repr},
 * ECMAScript's {@code Number::toString} and Python's {@code format(x, "g")}.
 *
 * <p>All start from the shortest decimal digits that read back as the same double (what Python
 * and JavaScript both print). Java 17's {@code Double.toString} does not always give the
 * shortest, so the digits are found here: for each length the nearest decimal of that many
 * digits, and the ones just below and above it, since near a power of two the interval that
 * reads back is lopsided and the nearest may fall outside it while another does not.
 */
public final class Numbers {
  private Numbers() {}

  /** The shortest digits of a finite, positive double and its decimal point position. */
  record Digits(String digits, int point) {
    // digits d1 d2 ... stand for 0.d1d2... x 10^point
  }

  static Digits shortest(double value) {
    BigDecimal exact = new BigDecimal(value);
    for (int precision = 1; precision <= 17; precision++) {
      BigDecimal nearest = exact.round(new MathContext(precision, RoundingMode.HALF_EVEN));
      BigDecimal chosen = null;
      if (nearest.doubleValue() == value) {
        chosen = nearest;
      } else {
        BigDecimal down = exact.round(new MathContext(precision, RoundingMode.FLOOR));
        BigDecimal up = exact.round(new MathContext(precision, RoundingMode.CEILING));
        boolean downReads = down.doubleValue() == value;
        boolean upReads = up.doubleValue() == value;
        if (downReads && upReads) {
          BigDecimal toDown = exact.subtract(down);
          BigDecimal toUp = up.subtract(exact);
          chosen = toDown.compareTo(toUp) <= 0 ? down : up;
        } else if (downReads) {
          chosen = down;
        } else if (upReads) {
          chosen = up;
        }
      }
      if (chosen != null) {
        BigDecimal stripped = chosen.stripTrailingZeros();
        String digits = stripped.unscaledValue().toString();
        int point = digits.length() - stripped.scale();
        return new Digits(digits, point);
      }
    }
    throw new AssertionError("17 digits always read back: " + value);
  }

  /** Python's {@code repr(float)}: "1.0", "0.1", "1e-05", "1.5e+16", "inf", "nan". */
  public static String pythonRepr(double value) {
    if (Double.isNaN(value)) {
      return "nan";
    }
    if (Double.isInfinite(value)) {
      return value > 0 ? "inf" : "-inf";
    }
    if (value == 0) {
      return (1 / value < 0) ? "-0.0" : "0.0";
    }
    if (value < 0) {
      return "-" + pythonRepr(-value);
    }
    Digits d = shortest(value);
    String digits = d.digits();
    int exponent = d.point() - 1;
    if (exponent >= -5 + 1 && exponent < 16) {
      return fixed(digits, d.point(), true);
    }
    String mantissa = digits.length() == 1 ? digits : digits.charAt(0) + "." + digits.substring(1);
    return mantissa + exponentText(exponent, 2);
  }

  /** Python's {@code repr} of a float inside JSON ({@code json.dumps}): NaN and Infinity as JS. */
  public static String pythonJson(double value) {
    if (Double.isNaN(value)) {
      return "NaN";
    }
    if (Double.isInfinite(value)) {
      return value > 0 ? "Infinity" : "-Infinity";
    }
    return pythonRepr(value);
  }

  /** ECMAScript's Number::toString (what JSON.stringify writes): "1", "0.5", "1e+21", "1e-7". */
  public static String ecmascript(double value) {
    if (Double.isNaN(value)) {
      return "NaN";
    }
    if (Double.isInfinite(value)) {
      return value > 0 ? "Infinity" : "-Infinity";
    }
    if (value == 0) {
      return "0";
    }
    if (value < 0) {
      return "-" + ecmascript(-value);
    }
    Digits d = shortest(value);
    String digits = d.digits();
    int point = d.point();
    int count = digits.length();
    if (count <= point && point <= 21) {
      return digits + "0".repeat(point - count);
    }
    if (0 < point && point <= 21) {
      return digits.substring(0, point) + "." + digits.substring(point);
    }
    if (-6 < point && point <= 0) {
      return "0." + "0".repeat(-point) + digits;
    }
    int power = point - 1;
    String mantissa = count == 1 ? digits : digits.charAt(0) + "." + digits.substring(1);
    return mantissa + "e" + (power >= 0 ? "+" : "-") + Math.abs(power);
  }

  /** Python's {@code f"{value:g}"}: 6 significant digits, trailing zeros dropped. */
  public static String pythonG(double value) {
    if (Double.isNaN(value)) {
      return "nan";
    }
    if (Double.isInfinite(value)) {
      return value > 0 ? "inf" : "-inf";
    }
    if (value == 0) {
      return (1 / value < 0) ? "-0" : "0";
    }
    if (value < 0) {
      return "-" + pythonG(-value);
    }
    BigDecimal rounded =
        new BigDecimal(value).round(new MathContext(6, RoundingMode.HALF_EVEN)).stripTrailingZeros();
    String digits = rounded.unscaledValue().toString();
    int point = digits.length() - rounded.scale();
    int exponent = point - 1;
    if (exponent >= -4 && exponent < 6) {
      return fixed(digits, point, false);
    }
    String mantissa = digits.length() == 1 ? digits : digits.charAt(0) + "." + digits.substring(1);
    return mantissa + exponentText(exponent, 2);
  }

  private static String fixed(String digits, int point, boolean pointZero) {
    int count = digits.length();
    if (point <= 0) {
      return "0." + "0".repeat(-point) + digits;
    }
    if (point >= count) {
      return digits + "0".repeat(point - count) + (pointZero ? ".0" : "");
    }
    return digits.substring(0, point) + "." + digits.substring(point);
  }

  private static String exponentText(int exponent, int minDigits) {
    String number = Integer.toString(Math.abs(exponent));
    if (number.length() < minDigits) {
      number = "0".repeat(minDigits - number.length()) + number;
    }
    return "e" + (exponent < 0 ? "-" : "+") + number;
  }
}
