package feelmysign.simplify;

import feelmysign.json.Numbers;
import java.math.BigInteger;

/**
 * One parameter of a simplifier: its name, kind, allowed range (inclusive; null: unbounded)
 * and help, as the reference's {@code ParamSpec} (written to {@code testdata/*}/params.json);
 * {@link Algorithm} makes them from the generated {@link ParamTable}.
 */
public record ParamSpec(String name, Kind kind, Double minimum, Double maximum, String help) {

  /** The JSON type a value must have. */
  public enum Kind {
    BOOLEAN("boolean"),
    INTEGER("integer"),
    NUMBER("number");

    private final String jsonName;

    Kind(String jsonName) {
      this.jsonName = jsonName;
    }

    /** "boolean", "integer" or "number", as in the parameter tables. */
    public String jsonName() {
      return jsonName;
    }
  }

  /**
   * Refuse a value of the wrong kind or out of range, with the reference's sentence.
   *
   * @throws ParameterException naming the parameter, the value and what it must be
   */
  public void check(Object value) {
    if (kind == Kind.BOOLEAN) {
      if (!(value instanceof Boolean)) {
        throw new ParameterException(name, value, "true or false");
      }
      return;
    }
    if (!isNumber(value)) {
      throw new ParameterException(name, value, "a number in " + rangeText());
    }
    double number = toDouble(value);
    if (kind == Kind.INTEGER && !isWhole(value)) {
      throw new ParameterException(name, value, "a whole number in " + rangeText());
    }
    if (!Double.isFinite(number) || !inRange(number)) {
      throw new ParameterException(name, value, "in " + rangeText());
    }
  }

  private boolean inRange(double value) {
    boolean lowOk = minimum == null || value >= minimum;
    boolean highOk = maximum == null || value <= maximum;
    return lowOk && highOk;
  }

  /** "[2, 600]": the bounds as Python's {@code format(bound, "g")} writes them. */
  public String rangeText() {
    return "[" + bound(minimum) + ", " + bound(maximum) + "]";
  }

  private static String bound(Double bound) {
    return bound == null ? "unbounded" : Numbers.pythonG(bound);
  }

  static boolean isNumber(Object value) {
    return value instanceof Long
        || value instanceof Integer
        || value instanceof Short
        || value instanceof Byte
        || value instanceof BigInteger
        || value instanceof Double
        || value instanceof Float;
  }

  static double toDouble(Object value) {
    if (value instanceof BigInteger big) {
      return big.doubleValue();
    }
    return ((Number) value).doubleValue();
  }

  /** Python's {@code float(value).is_integer()} (an int always is; float(huge int) overflows). */
  private static boolean isWhole(Object value) {
    if (value instanceof Double || value instanceof Float) {
      double d = ((Number) value).doubleValue();
      return Double.isFinite(d) && d == Math.rint(d);
    }
    return true;
  }
}
