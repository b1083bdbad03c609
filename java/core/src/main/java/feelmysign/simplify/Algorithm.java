package feelmysign.simplify;

import java.util.Collections;
import java.util.EnumMap;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * The simplifiers by name, as the reference's registry: each one's parameters in their order,
 * with defaults and ranges (from the generated {@link ParamTable}), and what it is fed
 * ({@code frames} resampled at {@code fps}, or every pointer {@code samples}).
 */
public enum Algorithm {
  /** The paper's turn-angle rule (section 4.4, appendix B.4), fed animation frames. */
  ANGLE("angle", "the paper's turn-angle rule", true),
  /** Error-bounded, cut at features, fed every pointer sample. */
  WINDOW("window", "error-bounded, cut at features", false);

  /** The project's choice (docs/research.md, "Default settings"): the table's default. */
  public static final Algorithm DEFAULT = named(ParamTable.DEFAULT_ALGORITHM);
  /** The paper's. */
  public static final Algorithm PAPER = ANGLE;

  private final String wireName;
  private final String summary;
  private final boolean frames;

  Algorithm(String wireName, String summary, boolean frames) {
    this.wireName = wireName;
    this.summary = summary;
    this.frames = frames;
  }

  /** "angle" or "window", as recordings, vectors and the command line name it. */
  public String wireName() {
    return wireName;
  }

  public String summary() {
    return summary;
  }

  /** Whether it is fed animation frames (angle) rather than every sample (window). */
  public boolean takesFrames() {
    return frames;
  }

  /** The algorithm named {@code name} ("angle" or "window"), or null. */
  public static Algorithm named(String name) {
    for (Algorithm algorithm : values()) {
      if (algorithm.wireName.equals(name)) {
        return algorithm;
      }
    }
    return null;
  }

  /** Its parameters in their order (the reference's dataclass fields), with their defaults. */
  public Map<String, Object> defaults() {
    return Tables.DEFAULTS.get(this);
  }

  /** Its parameter table, by name. */
  public Map<String, ParamSpec> specs() {
    return Tables.SPECS.get(this);
  }

  /** A new streaming simplifier with these parameters. */
  public Simplifier make(Params params) {
    if (params.algorithm() != this) {
      throw new IllegalArgumentException(
          "parameters of the " + params.algorithm().wireName + " simplifier given to " + wireName);
    }
    return this == ANGLE ? new AngleSimplifier(params) : new WindowSimplifier(params);
  }

  /** What this simplifier is fed for one path drawn as {@code samples}. */
  public List<Sample> inputs(Params params, List<Sample> samples) {
    if (frames) {
      return Frames.fromSamples(samples, params.fps());
    }
    return samples;
  }

  /** The parameters only one algorithm has, and which: giving one to the other is an error. */
  public static Map<String, Algorithm> onlyFor() {
    return Tables.ONLY_FOR;
  }

  /**
   * The tables, built once from the generated {@link ParamTable} (the reference's declarations):
   * each algorithm's parameters in its order, with defaults and ranges.
   */
  static final class Tables {
    private Tables() {}

    static final Map<Algorithm, Map<String, ParamSpec>> SPECS = new EnumMap<>(Algorithm.class);
    static final Map<Algorithm, Map<String, Object>> DEFAULTS = new EnumMap<>(Algorithm.class);
    // In the table's order, as the reference's ONLY_FOR (the first one given is the one told).
    static final Map<String, Algorithm> ONLY_FOR;

    static {
      Map<String, ParamTable.Row> rows = new LinkedHashMap<>();
      for (ParamTable.Row row : ParamTable.PARAMETERS) {
        rows.put(row.name(), row);
      }
      for (Algorithm algorithm : values()) {
        List<String> names = ParamTable.ALGORITHMS.get(algorithm.wireName);
        if (names == null) {
          throw new IllegalStateException("ParamTable has no " + algorithm.wireName);
        }
        Map<String, ParamSpec> specs = new LinkedHashMap<>();
        Map<String, Object> defaults = new LinkedHashMap<>();
        for (String name : names) {
          ParamTable.Row row = rows.get(name);
          specs.put(
              name, new ParamSpec(name, row.kind(), row.minimum(), row.maximum(), row.help()));
          defaults.put(name, row.defaultValue());
        }
        SPECS.put(algorithm, Collections.unmodifiableMap(specs));
        DEFAULTS.put(algorithm, Collections.unmodifiableMap(defaults));
      }
      Map<String, Algorithm> onlyFor = new LinkedHashMap<>();
      for (ParamTable.Row row : ParamTable.PARAMETERS) {
        if (row.algorithms().size() == 1) {
          onlyFor.put(row.name(), named(row.algorithms().get(0)));
        }
      }
      ONLY_FOR = Collections.unmodifiableMap(onlyFor);
    }
  }
}
