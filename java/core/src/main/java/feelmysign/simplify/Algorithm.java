package feelmysign.simplify;

import java.util.ArrayList;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * The simplifiers by name, as the reference's registry: each one's parameters in their order,
 * with defaults and ranges, and what it is fed ({@code frames} resampled at {@code fps}, or
 * every pointer {@code samples}).
 */
public enum Algorithm {
  /** The paper's turn-angle rule (section 4.4, appendix B.4), fed animation frames. */
  ANGLE("angle", "the paper's turn-angle rule", true),
  /** Error-bounded, cut at features, fed every pointer sample. */
  WINDOW("window", "error-bounded, cut at features", false);

  /** The project's choice (docs/research.md, "Default settings"). */
  public static final Algorithm DEFAULT = WINDOW;
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
    return this == ANGLE ? Tables.ANGLE_DEFAULTS : Tables.WINDOW_DEFAULTS;
  }

  /** Its parameter table, by name. */
  public Map<String, ParamSpec> specs() {
    return this == ANGLE ? Tables.ANGLE_SPECS : Tables.WINDOW_SPECS;
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

  /** The tables, built once. */
  static final class Tables {
    private Tables() {}

    // The drop and grid settings every simplifier has (beside its own).
    static final List<ParamSpec> DROP_AND_GRID =
        List.of(
            ParamSpec.bool("clear_on_press", "a new press clears the drawing"),
            ParamSpec.number("min_duration_ms", 0, 10_000, "shortest stroke to send, in ms"),
            ParamSpec.number("min_length", 0, 100, "shortest stroke to send, in grid units"),
            ParamSpec.integer("rows", 1, 64, "actuator rows of the sleeve"),
            ParamSpec.integer("columns", 1, 64, "actuator columns of the sleeve"),
            ParamSpec.number("canvas_width_px", 1, 100_000, "drawing area width in pixels"),
            ParamSpec.number("canvas_height_px", 1, 100_000, "drawing area height in pixels"),
            ParamSpec.bool("stretch", "stretch the canvas onto the grid (the paper's)"));

    static final Map<String, ParamSpec> ANGLE_SPECS =
        table(
            List.of(
                ParamSpec.integer(
                    "check_frames", 2, 600, "frames between two checks (the paper's checkFrame)"),
                ParamSpec.number(
                    "max_angle_deg", 1, 179, "largest turn, in degrees, that continues a line"),
                ParamSpec.integer("frame_max", 0, 36_000, "longest line in frames; 0 = no limit"),
                ParamSpec.bool("recover", "start a new line at the last check (no gaps)"),
                ParamSpec.number("fps", 1, 1000, "frames per second of the drawing loop")),
            DROP_AND_GRID);

    static final Map<String, ParamSpec> WINDOW_SPECS =
        table(
            List.of(
                ParamSpec.number(
                    "max_error",
                    0.001,
                    100,
                    "farthest a drawn point may lie from its stroke, in grid units"),
                ParamSpec.integer(
                    "max_window",
                    1,
                    10_000,
                    "longest stroke in samples after its start (bounds the work per sample)"),
                ParamSpec.number(
                    "max_stroke_ms",
                    0,
                    60_000,
                    "longest stroke in ms of drawing, so a long line is felt before it ends; "
                        + "0 = no limit")),
            DROP_AND_GRID);

    static final Map<String, Object> ANGLE_DEFAULTS =
        ordered(
            "check_frames", 5L,
            "max_angle_deg", 20.0,
            "frame_max", 0L,
            "fps", 60.0,
            "recover", true,
            "clear_on_press", true,
            "min_duration_ms", 6.1,
            "min_length", 0.1,
            "rows", 3L,
            "columns", 4L,
            "canvas_width_px", 1920.0,
            "canvas_height_px", 1080.0,
            "stretch", false);

    // The project's defaults (docs/research.md, "Default settings"): max_error 0.25 grid units
    // is 7.5 mm on the paper's sleeve, well below the forearm's two-point threshold; strokes of
    // at most 300 ms keep the felt drawing within about a third of a second of the pen.
    static final Map<String, Object> WINDOW_DEFAULTS =
        ordered(
            "max_error", 0.25,
            "max_window", 256L,
            "max_stroke_ms", 300.0,
            "clear_on_press", true,
            "min_duration_ms", 6.1,
            "min_length", 0.1,
            "rows", 3L,
            "columns", 4L,
            "canvas_width_px", 1920.0,
            "canvas_height_px", 1080.0,
            "stretch", false);

    static final Map<String, Algorithm> ONLY_FOR = onlyForTable();

    private static Map<String, ParamSpec> table(List<ParamSpec> own, List<ParamSpec> shared) {
      Map<String, ParamSpec> out = new LinkedHashMap<>();
      for (ParamSpec spec : own) {
        out.put(spec.name(), spec);
      }
      for (ParamSpec spec : shared) {
        out.put(spec.name(), spec);
      }
      return Collections.unmodifiableMap(out);
    }

    private static Map<String, Object> ordered(Object... pairs) {
      Map<String, Object> out = new LinkedHashMap<>();
      for (int i = 0; i < pairs.length; i += 2) {
        out.put((String) pairs[i], pairs[i + 1]);
      }
      return Collections.unmodifiableMap(out);
    }

    private static Map<String, Algorithm> onlyForTable() {
      Map<String, List<Algorithm>> owners = new LinkedHashMap<>();
      for (Map<String, ParamSpec> specs : List.of(ANGLE_SPECS, WINDOW_SPECS)) {
        Algorithm algorithm = specs == ANGLE_SPECS ? ANGLE : WINDOW;
        for (String name : specs.keySet()) {
          owners.computeIfAbsent(name, k -> new ArrayList<>()).add(algorithm);
        }
      }
      Map<String, Algorithm> out = new LinkedHashMap<>();
      owners.forEach(
          (name, list) -> {
            if (list.size() == 1) {
              out.put(name, list.get(0));
            }
          });
      return Collections.unmodifiableMap(out);
    }
  }
}
