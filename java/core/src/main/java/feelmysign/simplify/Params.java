package feelmysign.simplify;

import java.util.ArrayList;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * The parameters of one simplifier: every one of its settings, checked against its table when
 * made, immutable. As the reference's {@code AngleParams} and {@code WindowParams}: the same
 * names, defaults, ranges and error sentences, and a value keeps the kind it was given (5 stays
 * the integer 5, 5.0 the float 5.0), as Python's dataclasses keep it.
 *
 * <p>Every name, default and range comes from the generated {@link ParamTable}, the reference's
 * declarations. Besides the reference's names, the paper's appendix B.1 names (the table's
 * {@code paper} column) are understood:
 * {@code frameMax}, {@code checkFrame}, {@code maxAngleDifDeg}, {@code fps}, {@code clickClear},
 * {@code recover}, {@code sleeveX} and {@code sleeveY} (the last actuator's index, counted from
 * 0, so one less than the columns and rows), {@code screenX}, {@code screenY},
 * {@code minimumDuration} (ms) and {@code minimumSize} (grid units).
 *
 * <pre>
 * Params p = Params.angle().with("checkFrame", 5).with("maxAngleDifDeg", 20);
 * </pre>
 */
public final class Params {
  private final Algorithm algorithm;
  private final Map<String, Object> values;

  private Params(Algorithm algorithm, Map<String, Object> values) {
    this.algorithm = algorithm;
    this.values = Collections.unmodifiableMap(values);
  }

  /** The angle simplifier at the paper's defaults (appendix B.1). */
  public static Params angle() {
    return of(Algorithm.ANGLE, Map.of());
  }

  /** The window simplifier at the project's defaults. */
  public static Params window() {
    return of(Algorithm.WINDOW, Map.of());
  }

  /**
   * {@code algorithm}'s defaults with {@code given} over them, every field then checked in the
   * reference's order (the first one out of range is reported).
   *
   * @throws ParameterException for a value of the wrong kind or out of range
   * @throws IllegalArgumentException for a name the algorithm does not have
   */
  public static Params of(Algorithm algorithm, Map<String, ?> given) {
    Map<String, Object> values = new LinkedHashMap<>(algorithm.defaults());
    Map<String, Object> resolved = new LinkedHashMap<>();
    for (Map.Entry<String, ?> entry : given.entrySet()) {
      Alias alias = Alias.of(entry.getKey());
      String name = alias == null ? entry.getKey() : alias.canonical;
      Object value = normalized(entry.getValue());
      if (!values.containsKey(name)) {
        throw unknown(algorithm, entry.getKey());
      }
      if (alias != null) {
        // Checked in the paper's terms first, so the message names what was given.
        alias.spec(algorithm).check(value);
        value = alias.toCanonical(value);
      }
      resolved.put(name, value);
    }
    values.putAll(resolved);
    for (Map.Entry<String, Object> entry : values.entrySet()) {
      algorithm.specs().get(entry.getKey()).check(entry.getValue());
    }
    return new Params(algorithm, values);
  }

  /** These parameters with one changed (a reference name or a paper name). */
  public Params with(String name, Object value) {
    Map<String, Object> given = new LinkedHashMap<>(values);
    Alias alias = Alias.of(name);
    if (alias != null) {
      given.remove(alias.canonical);
    }
    given.put(name, value);
    return of(algorithm, given);
  }

  public Algorithm algorithm() {
    return algorithm;
  }

  /** Every parameter in the reference's order, each as given (Boolean, Long or Double). */
  public Map<String, Object> values() {
    return values;
  }

  public Object get(String name) {
    Alias alias = Alias.of(name);
    String canonical = alias == null ? name : alias.canonical;
    if (!values.containsKey(canonical)) {
      throw unknown(algorithm, name);
    }
    Object value = values.get(canonical);
    return alias == null ? value : alias.fromCanonical(value);
  }

  public double number(String name) {
    return ParamSpec.toDouble(get(name));
  }

  public int integer(String name) {
    return (int) ParamSpec.toDouble(get(name));
  }

  public boolean flag(String name) {
    return (Boolean) get(name);
  }

  public int rows() {
    return integer("rows");
  }

  public int columns() {
    return integer("columns");
  }

  public double fps() {
    return number("fps");
  }

  /** The canvas-to-grid mapping of these parameters. */
  public CanvasMapping mapping() {
    return new CanvasMapping(
        number("canvas_width_px"), number("canvas_height_px"), columns(), rows(), flag("stretch"));
  }

  private static Object normalized(Object value) {
    if (value instanceof Integer || value instanceof Short || value instanceof Byte) {
      return ((Number) value).longValue();
    }
    if (value instanceof Float f) {
      // The double that prints as the float does: 0.1f is 0.1, not 0.10000000149011612 (its
      // exact value). A float is what Processing's literals are; what was written is meant.
      return Double.parseDouble(Float.toString(f));
    }
    return value;
  }

  private static IllegalArgumentException unknown(Algorithm algorithm, String name) {
    Alias alias = Alias.of(name);
    Algorithm owner = Algorithm.onlyFor().get(alias == null ? name : alias.canonical);
    if (owner != null && owner != algorithm) {
      return new IllegalArgumentException(
          name + " only applies to the " + owner.wireName() + " simplifier");
    }
    return new IllegalArgumentException(
        "the "
            + algorithm.wireName()
            + " simplifier has no parameter "
            + name
            + "; its parameters are "
            + String.join(", ", algorithm.defaults().keySet())
            + " (or the paper's names: "
            + String.join(", ", Alias.namesOf(algorithm))
            + ")");
  }

  @Override
  public boolean equals(Object other) {
    return other instanceof Params p && p.algorithm == algorithm && p.values.equals(values);
  }

  @Override
  public int hashCode() {
    return algorithm.hashCode() * 31 + values.hashCode();
  }

  @Override
  public String toString() {
    return algorithm.wireName() + " " + values;
  }

  /**
   * A name of the paper's appendix B.1 that is not the reference's, and the reference parameter
   * it stands for: the {@code paper} column of the generated {@link ParamTable}.
   */
  private static final class Alias {
    static final Map<String, Alias> NAMES = new LinkedHashMap<>();

    static {
      for (ParamTable.Row row : ParamTable.PARAMETERS) {
        // fps and recover are named as the paper names them: nothing to translate.
        if (row.paper() != null && !row.paper().equals(row.name())) {
          NAMES.put(row.paper(), new Alias(row.paper(), row.name(), row.paperOffset()));
        }
      }
    }

    final String name;
    final String canonical;
    final long offset;

    private Alias(String name, String canonical, long offset) {
      this.name = name;
      this.canonical = canonical;
      this.offset = offset;
    }

    static Alias of(String name) {
      return NAMES.get(name);
    }

    /** The paper's names of {@code algorithm}'s parameters, in the table's order. */
    static List<String> namesOf(Algorithm algorithm) {
      List<String> out = new ArrayList<>();
      for (Alias alias : NAMES.values()) {
        if (algorithm.specs().containsKey(alias.canonical)) {
          out.add(alias.name);
        }
      }
      return out;
    }

    ParamSpec spec(Algorithm algorithm) {
      ParamSpec spec = algorithm.specs().get(canonical);
      if (offset == 0) {
        return new ParamSpec(name, spec.kind(), spec.minimum(), spec.maximum(), spec.help());
      }
      return new ParamSpec(
          name, spec.kind(), spec.minimum() - offset, spec.maximum() - offset, spec.help());
    }

    Object toCanonical(Object value) {
      if (offset == 0 || !ParamSpec.isNumber(value)) {
        return value;
      }
      if (value instanceof Long l) {
        return l + offset;
      }
      return ParamSpec.toDouble(value) + offset;
    }

    Object fromCanonical(Object value) {
      if (offset == 0) {
        return value;
      }
      if (value instanceof Long l) {
        return l - offset;
      }
      return ParamSpec.toDouble(value) - offset;
    }
  }
}
