package feelmysign.cli;

import feelmysign.json.Numbers;
import feelmysign.json.PyDumps;
import feelmysign.json.PyRepr;
import feelmysign.simplify.Algorithm;
import feelmysign.simplify.ParamSpec;
import feelmysign.simplify.ParamTable;
import feelmysign.simplify.Params;
import feelmysign.simplify.PathSegment;
import feelmysign.simplify.Recording;
import feelmysign.simplify.RecordingException;
import feelmysign.simplify.Segment;
import feelmysign.simplify.Simplify;
import java.io.IOException;
import java.io.PrintStream;
import java.math.BigDecimal;
import java.math.RoundingMode;
import java.nio.file.AccessDeniedException;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.NoSuchFileException;
import java.nio.file.NotDirectoryException;
import java.nio.file.Path;
import java.nio.file.attribute.BasicFileAttributes;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Set;

/**
 * {@code feelmysign-java simplify RECORDING [flags] [--json]}: a recorded drawing through a
 * simplifier, with the flags of the reference's {@code feelmysign simplify} and, with
 * {@code --json}, the same JSON to the byte, so the two ports can be compared on any recording.
 */
final class SimplifyCommand {
  private SimplifyCommand() {}

  static final String PROG = Main.PROG + " simplify";
  /** An hour of drawing at 240 samples a second is ~60 MiB. */
  static final long MAX_RECORDING_BYTES = 64L * 1024 * 1024;

  /** What a flag does: takes a number, a whole number or a choice, or sets true or false. */
  private enum Kind {
    FLOAT,
    INT,
    CHOICE,
    TRUE,
    FALSE,
    HELP
  }

  /** One name of an option: the parameter it sets and how, and the option's name in errors
   * (its names joined by '/', as argparse names it). */
  private record Flag(String flag, String dest, Kind kind, String action) {}

  // The parameters that change the strokes of a recording get an option, as in the reference:
  // the simplifier's and the grid's; the canvas is the recording's, clearing on a press the page's.
  private static final Set<String> CLI_PANELS = Set.of("simplifier", "sleeve");
  // A number option's placeholder, by its unit, as the reference's.
  private static final Map<String, String> METAVARS =
      Map.of("ms", "MS", "\u00b0", "DEG", "grid units", "UNITS", "fps", "FPS", "px", "PX");
  private static final String DESCRIPTION =
      "Run a recording (JSON: canvas size and pointer samples per path; see docs/research.md)"
          + " through a simplifier, exactly as the drawing client would, and show the strokes it"
          + " sends and the ones it drops. An option not given takes the recording's value (its"
          + " simplifier's settings, its sleeve's grid), else its default.";

  private static final List<ArgparseHelp.Argument> ARGUMENTS = new ArrayList<>();
  private static final List<Flag> FLAGS = new ArrayList<>();

  static {
    flags(Kind.HELP, "help", null, "show this help message and exit", "-h", "--help");
    String choices = "{" + String.join(",", ParamTable.ALGORITHMS.keySet()) + "}";
    flags(
        Kind.CHOICE,
        "algorithm",
        choices,
        "the simplifier: angle (the paper's) or window (error-bounded, cut at features);"
            + " default: the recording's, else "
            + ParamTable.DEFAULT_ALGORITHM,
        "--algorithm");
    flags(
        Kind.TRUE,
        "paper",
        null,
        "the paper's settings: the angle simplifier at its appendix B.1 values (the same as"
            + " --algorithm "
            + Algorithm.PAPER.wireName()
            + ")",
        "--paper");
    for (ParamTable.Row row : ParamTable.PARAMETERS) {
      if (row.panel() != null && CLI_PANELS.contains(row.panel())) {
        parameter(row);
      }
    }
    flags(Kind.TRUE, "json", null, "print the strokes as JSON", "--json");
    ARGUMENTS.add(
        new ArgparseHelp.Argument("RECORDING", "RECORDING", "a recording JSON file", true));
  }

  /** The option of one parameter, its help and range from the table, as the reference's. */
  private static void parameter(ParamTable.Row row) {
    String prefix = row.algorithms().size() == 1 ? row.algorithms().get(0) + ": " : "";
    if (row.onlyWhen() != null) { // read by one of its simplifier's cores only
      prefix =
          prefix.substring(0, prefix.length() - 2)
              + " with "
              + switchFlag(row.onlyWhen().name(), row.onlyWhen().value())
              + ": ";
    }
    String flag = "--" + row.name().replace('_', '-');
    if (row.kind() == ParamSpec.Kind.BOOLEAN) {
      String onOff = Boolean.TRUE.equals(row.defaultValue()) ? "on" : "off";
      String help = prefix + row.help() + " (default: " + onOff + ")";
      // argparse's BooleanOptionalAction: --recover and --no-recover, listed together.
      String no = "--no-" + flag.substring(2);
      ARGUMENTS.add(
          new ArgparseHelp.Argument(flag + ", " + no, "[" + flag + " | " + no + "]", help, false));
      FLAGS.add(new Flag(flag, row.name(), Kind.TRUE, flag + "/" + no));
      FLAGS.add(new Flag(no, row.name(), Kind.FALSE, flag + "/" + no));
      return;
    }
    boolean whole = row.kind() == ParamSpec.Kind.INTEGER;
    String metavar = whole ? "N" : METAVARS.getOrDefault(row.unit() == null ? "" : row.unit(), "X");
    String help =
        prefix
            + row.help()
            + " ("
            + bound(row.minimum())
            + " to "
            + bound(row.maximum())
            + "; default: "
            + Numbers.pythonG(((Number) row.defaultValue()).doubleValue())
            + ")";
    flags(whole ? Kind.INT : Kind.FLOAT, row.name(), metavar, help, flag);
  }

  private static String bound(Double value) {
    return value == null ? "unbounded" : Numbers.pythonG(value);
  }

  /** An option of one or more names (listed together), taking {@code metavar} or nothing. */
  private static void flags(Kind kind, String dest, String metavar, String help, String... names) {
    String argument = metavar == null ? "" : " " + metavar;
    List<String> invocations = new ArrayList<>();
    for (String name : names) {
      invocations.add(name + argument);
      FLAGS.add(new Flag(name, dest, kind, String.join("/", names)));
    }
    ARGUMENTS.add(
        new ArgparseHelp.Argument(
            String.join(", ", invocations), "[" + names[0] + argument + "]", help, false));
  }

  private static final ArgparseHelp HELP = new ArgparseHelp(PROG, DESCRIPTION, ARGUMENTS);

  static int run(String[] args, PrintStream out, PrintStream err) {
    Map<String, Object> given = parse(args);
    if (given.containsKey("help")) {
      out.print(HELP.help());
      return 0;
    }
    String path = (String) given.get("recording");
    Recording recording = load(path);
    Algorithm algorithm = chosenAlgorithm(given, recording, path);
    checkUsage(given, algorithm);
    Params params = params(given, recording, algorithm);
    checkConditions(given, params);
    List<PathSegment> result = Simplify.paths(params, recording.paths());
    if (given.containsKey("json")) {
      out.println(PyDumps.dumps(toJson(result, params)));
    } else {
      out.println(describe(result, params, path));
    }
    return 0;
  }

  // --- the command line, as argparse reads it ----------------------------------------------

  private static Main.UsageException usage(String message) {
    return new Main.UsageException(PROG, message);
  }

  private static Map<String, Object> parse(String[] args) {
    Map<String, Object> given = new LinkedHashMap<>();
    List<String> positionals = new ArrayList<>();
    List<String> unrecognized = new ArrayList<>();
    boolean onlyPositionals = false;
    for (int i = 0; i < args.length; i++) {
      String arg = args[i];
      if (onlyPositionals || !arg.startsWith("-") || arg.equals("-") || isNegativeNumber(arg)) {
        positionals.add(arg);
        continue;
      }
      if (arg.equals("--")) {
        onlyPositionals = true;
        continue;
      }
      String name = arg;
      String explicit = null;
      int equals = arg.indexOf('=');
      if (arg.startsWith("--") && equals > 0) {
        name = arg.substring(0, equals);
        explicit = arg.substring(equals + 1);
      }
      Flag option = find(name, arg);
      if (option == null) {
        unrecognized.add(arg);
        continue;
      }
      switch (option.kind()) {
        case TRUE, FALSE, HELP -> {
          if (explicit != null) {
            throw usage(
                "argument "
                    + option.action()
                    + ": ignored explicit argument "
                    + PyRepr.of(explicit));
          }
          given.put(option.dest(), option.kind() != Kind.FALSE);
        }
        default -> {
          String value = explicit;
          if (value == null) {
            if (i + 1 >= args.length
                || (args[i + 1].startsWith("-")
                    && !args[i + 1].equals("-")
                    && !isNegativeNumber(args[i + 1]))) {
              throw usage("argument " + option.action() + ": expected one argument");
            }
            value = args[++i];
          }
          given.put(option.dest(), convert(option, value));
        }
      }
    }
    if (given.containsKey("help")) {
      return given;
    }
    if (positionals.size() > 1) {
      unrecognized.addAll(0, positionals.subList(1, positionals.size()));
    }
    if (positionals.isEmpty()) {
      throw usage("the following arguments are required: RECORDING");
    }
    if (!unrecognized.isEmpty()) {
      throw usage("unrecognized arguments: " + String.join(" ", unrecognized));
    }
    given.put("recording", positionals.get(0));
    return given;
  }

  /** The reference's test: '-' then a digit (or '-.' then one) is a number, never an option;
   * so is anything with a space in it, as argparse reads it. */
  private static boolean isNegativeNumber(String arg) {
    return arg.matches("^-\\.?\\d.*") || (arg.startsWith("-") && arg.contains(" "));
  }

  /** An option by its name or a unique prefix of it ({@code arg} as given), as argparse allows. */
  private static Flag find(String name, String arg) {
    List<Flag> matches = new ArrayList<>();
    for (Flag flag : FLAGS) {
      if (flag.flag().equals(name)) {
        return flag;
      }
      if (name.startsWith("--") && flag.flag().startsWith(name)) {
        matches.add(flag);
      }
    }
    if (matches.size() > 1) {
      List<String> flags = matches.stream().map(Flag::flag).toList();
      throw usage("ambiguous option: " + arg + " could match " + String.join(", ", flags));
    }
    return matches.isEmpty() ? null : matches.get(0);
  }

  private static Object convert(Flag option, String value) {
    switch (option.kind()) {
      case CHOICE -> {
        if (Algorithm.named(value) == null) {
          throw usage(
              "argument "
                  + option.action()
                  + ": invalid choice: "
                  + PyRepr.of(value)
                  + " (choose from "
                  + String.join(
                      ", ", ParamTable.ALGORITHMS.keySet().stream().map(PyRepr::of).toList())
                  + ")");
        }
        return value;
      }
      default -> {
        boolean whole = option.kind() == Kind.INT;
        // Not a conditional expression: it would make a Long a Double (numeric promotion).
        Object number;
        if (whole) {
          number = PythonNumbers.parseInt(value);
        } else {
          number = PythonNumbers.parseFloat(value);
        }
        if (number == null) {
          String wanted =
              whole
                  ? "a whole decimal number; write it with the digits 0-9, e.g. 3"
                  : "a decimal number; write it with the digits 0-9, e.g. 0.25, 12 or 2e-3";
          throw usage("argument " + option.action() + ": " + PyRepr.of(value) + " is not " + wanted);
        }
        checkRange(option, value, ((Number) number).doubleValue(), whole);
        return number;
      }
    }
  }

  /**
   * A value outside its parameter's range is a usage error naming the range, before any recording
   * is read, as the reference's ({@code _value_of} in feelmysign/cli/simplify.py).
   */
  private static void checkRange(Flag option, String text, double value, boolean whole) {
    for (ParamTable.Row row : ParamTable.PARAMETERS) {
      if (!row.name().equals(option.dest())) {
        continue;
      }
      Double low = row.minimum();
      Double high = row.maximum();
      boolean inRange =
          Double.isFinite(value) && (low == null || value >= low) && (high == null || value <= high);
      if (inRange) {
        return;
      }
      String kind = whole ? "a whole number" : "a number";
      String allowed;
      if (low != null && high != null) {
        allowed = kind + " from " + Numbers.pythonG(low) + " to " + Numbers.pythonG(high);
      } else if (low != null) {
        allowed = kind + " of " + Numbers.pythonG(low) + " or more";
      } else if (high != null) {
        allowed = kind + " of at most " + Numbers.pythonG(high);
      } else {
        allowed = kind;
      }
      if (row.unit() != null && !row.unit().isEmpty()) {
        allowed += " (" + row.unit() + ")";
      }
      throw usage("argument " + option.action() + ": " + text + " is out of range; give " + allowed);
    }
  }

  // --- the recording -------------------------------------------------------------------------

  /** The recording at {@code path}, refused up front if it is not a regular file of sane size. */
  private static Recording load(String path) {
    Path file = Path.of(path);
    try {
      BasicFileAttributes info = Files.readAttributes(file, BasicFileAttributes.class);
      String problem = null;
      if (info.isDirectory()) {
        problem = "is a folder: give the path of a file in it";
      } else if (!info.isRegularFile()) {
        problem =
            "is "
                + fileKind(file)
                + ", not a regular file: save it to a file first, then give that file's path";
      } else if (info.size() > MAX_RECORDING_BYTES) {
        problem =
            "holds "
                + sizeText(info.size())
                + "; at most "
                + sizeText(MAX_RECORDING_BYTES)
                + " is read: check that this is the right file";
      }
      if (problem != null) {
        throw new IllegalArgumentException("The recording " + PyRepr.of(path) + " " + problem + ".");
      }
    } catch (IOException error) {
      // Not there, or not readable: the loader says so in its own words.
    }
    byte[] data;
    try {
      data = Files.readAllBytes(file);
    } catch (NoSuchFileException | NotDirectoryException error) {
      throw new RecordingException(
          "cannot read recording " + path + ": No such file or directory");
    } catch (AccessDeniedException error) {
      throw new RecordingException("cannot read recording " + path + ": Permission denied");
    } catch (IOException error) {
      throw new RecordingException("cannot read recording " + path + ": " + error.getMessage());
    }
    return Recording.parse(Recording.decode(data, path), path);
  }

  private static String fileKind(Path file) {
    try {
      Object mode = Files.getAttribute(file, "unix:mode", LinkOption.NOFOLLOW_LINKS);
      int type = ((Integer) mode) & 0170000;
      return switch (type) {
        case 0010000 -> "a fifo (named pipe)";
        case 0020000, 0060000 -> "a device";
        case 0140000 -> "a socket";
        default -> "not a regular file";
      };
    } catch (IOException | UnsupportedOperationException | IllegalArgumentException error) {
      return "not a regular file";
    }
  }

  private static String sizeText(long bytes) {
    long kib = 1024;
    long mib = kib * 1024;
    if (bytes >= mib) {
      return fixed((double) bytes / mib, 1) + " MiB";
    }
    if (bytes >= kib) {
      return fixed((double) bytes / kib, 1) + " KiB";
    }
    return bytes + " bytes";
  }

  // --- parameters ----------------------------------------------------------------------------

  /** --paper or --algorithm, else the recording's sender's, else the default. */
  private static Algorithm chosenAlgorithm(
      Map<String, Object> given, Recording recording, String path) {
    if (given.containsKey("paper")) {
      return Algorithm.PAPER;
    }
    if (given.containsKey("algorithm")) {
      return Algorithm.named((String) given.get("algorithm"));
    }
    Object recorded = recordedAlgorithm(recording);
    Algorithm algorithm = recorded instanceof String name ? Algorithm.named(name) : null;
    if (algorithm == null) {
      throw new RecordingException(
          path
              + ": simplifier.algorithm "
              + PyRepr.of(recorded)
              + " is unknown; choose one with --algorithm angle|window");
    }
    return algorithm;
  }

  private static Object recordedAlgorithm(Recording recording) {
    Map<String, Object> simplifier = recording.simplifier();
    return simplifier.containsKey("algorithm")
        ? simplifier.get("algorithm")
        : Algorithm.DEFAULT.wireName();
  }

  /** Usage error (exit 2): an option of the other algorithm, which would be ignored. */
  private static void checkUsage(Map<String, Object> given, Algorithm algorithm) {
    Object chosen = given.get("algorithm");
    if (given.containsKey("paper") && chosen != null && !chosen.equals("angle")) {
      throw usage("--paper is the angle simplifier: drop --algorithm " + chosen);
    }
    for (Map.Entry<String, Algorithm> only : Algorithm.onlyFor().entrySet()) {
      String name = only.getKey();
      if (only.getValue() != algorithm && given.containsKey(name)) {
        String flag = (Boolean.FALSE.equals(given.get(name)) ? "--no-" : "--") + name.replace('_', '-');
        throw usage(flag + " only applies to --algorithm " + only.getValue().wireName());
      }
    }
  }

  /** The flag that sets a boolean parameter: --least-squares or --no-least-squares. */
  private static String switchFlag(String name, boolean value) {
    return (value ? "--" : "--no-") + name.replace('_', '-');
  }

  /**
   * Usage error (exit 2): an option its simplifier reads only under a setting (the table's
   * onlyWhen) that is off here, the recording's settings included, so it would change nothing.
   */
  private static void checkConditions(Map<String, Object> given, Params params) {
    for (ParamTable.Row row : ParamTable.PARAMETERS) {
      ParamTable.Condition condition = row.onlyWhen();
      String name = row.name();
      if (condition == null
          || !given.containsKey(name)
          || !params.algorithm().defaults().containsKey(name)
          || params.flag(condition.name()) == condition.value()) {
        continue;
      }
      String flag = (Boolean.FALSE.equals(given.get(name)) ? "--no-" : "--") + name.replace('_', '-');
      String wanted = switchFlag(condition.name(), condition.value());
      String fix;
      if (given.containsKey(condition.name())) {
        fix =
            "drop it, or give "
                + wanted
                + " instead of "
                + switchFlag(condition.name(), !condition.value());
      } else {
        ParamTable.Row switchRow = row(condition.name());
        String state = condition.value() ? "off" : "on";
        String label = switchRow.label().toLowerCase(Locale.ROOT);
        boolean byDefault = switchRow.defaultValue().equals(params.flag(condition.name()));
        String why =
            byDefault
                ? label + " is " + state + " by default"
                : "the recording's settings have " + label + " " + state;
        fix = "drop it, or add " + wanted + " (" + why + ")";
      }
      throw usage(flag + " only applies with " + wanted + "; " + fix);
    }
  }

  private static ParamTable.Row row(String name) {
    for (ParamTable.Row row : ParamTable.PARAMETERS) {
      if (row.name().equals(name)) {
        return row;
      }
    }
    throw new IllegalArgumentException("no parameter " + name);
  }

  /** The recording's own settings, then the command line's, over the algorithm's defaults. */
  private static Params params(Map<String, Object> given, Recording recording, Algorithm algorithm) {
    Set<String> names = algorithm.defaults().keySet();
    Map<String, Object> recorded = new LinkedHashMap<>();
    if (algorithm.wireName().equals(recordedAlgorithm(recording))
        && !given.containsKey("paper")) {
      Object settings =
          recording.simplifier().containsKey("params")
              ? recording.simplifier().get("params")
              : Map.of();
      if (!(settings instanceof Map<?, ?> map)) {
        throw new RecordingException(
            "simplifier.params must be an object of parameter names and values, got "
                + PyRepr.of(settings));
      }
      for (Map.Entry<?, ?> entry : map.entrySet()) {
        if (names.contains(entry.getKey())) {
          recorded.put((String) entry.getKey(), entry.getValue());
        }
      }
    }
    Params base = Params.of(algorithm, recorded);
    Map<String, Object> values = new LinkedHashMap<>(base.values());
    values.put("canvas_width_px", recording.widthPx());
    values.put("canvas_height_px", recording.heightPx());
    values.put("rows", recording.rows() != null ? (Object) (long) recording.rows() : base.get("rows"));
    values.put(
        "columns",
        recording.columns() != null ? (Object) (long) recording.columns() : base.get("columns"));
    for (String name : names) {
      if (given.containsKey(name)) {
        values.put(name, given.get(name));
      }
    }
    return Params.of(algorithm, values);
  }

  // --- output --------------------------------------------------------------------------------

  static Map<String, Object> toJson(List<PathSegment> result, Params params) {
    List<Object> strokes = new ArrayList<>();
    List<Object> dropped = new ArrayList<>();
    for (PathSegment item : result) {
      Segment s = item.segment();
      Map<String, Object> entry = new LinkedHashMap<>();
      if (s.dropped() != null) {
        entry.put("reason", s.dropped());
      }
      entry.put("start", List.of(s.startX(), s.startY()));
      entry.put("end", List.of(s.endX(), s.endY()));
      entry.put("start_ms", s.startMs());
      entry.put("end_ms", s.endMs());
      entry.put("duration_ms", s.durationMs());
      entry.put("path", (long) item.path());
      entry.put("emitted_at_ms", s.emittedAtMs());
      (s.dropped() == null ? strokes : dropped).add(entry);
    }
    Map<String, Object> out = new LinkedHashMap<>();
    out.put("algorithm", params.algorithm().wireName());
    out.put("params", params.values());
    out.put("strokes", strokes);
    out.put("dropped", dropped);
    return out;
  }

  static String describe(List<PathSegment> result, Params params, String source) {
    long sent = result.stream().filter(r -> r.segment().dropped() == null).count();
    Set<Integer> paths = new LinkedHashSet<>();
    result.forEach(r -> paths.add(r.path()));
    StringBuilder out = new StringBuilder();
    out.append(source)
        .append(": ")
        .append(paths.size())
        .append(" path(s) -> ")
        .append(sent)
        .append(" stroke(s) sent, ")
        .append(result.size() - sent)
        .append(" dropped (")
        .append(settings(params))
        .append("; ")
        .append(PyRepr.of(params.get("rows")))
        .append(" x ")
        .append(PyRepr.of(params.get("columns")))
        .append(" grid)\n\n");
    out.append(
        String.format(
            "%4s  %15s  %15s  %8s  %10s  note", "path", "start", "end", "ms", "emitted at"));
    for (PathSegment r : result) {
      Segment s = r.segment();
      String note = s.dropped() != null ? "dropped: " + s.dropped() : "";
      if (s.dropped() == null && s.durationMs() != s.drawnMs()) { // drawn briefer than the floor
        note = "at the sleeve's floor (drawn in " + fixed(s.drawnMs(), 1) + " ms)";
      }
      out.append('\n')
          .append(
              String.format(
                  "%4d  %15s  %15s  %8s  %10s  %s",
                  r.path(),
                  point(s.startX(), s.startY()),
                  point(s.endX(), s.endY()),
                  fixed(s.durationMs(), 1),
                  fixed(s.emittedAtMs(), 1),
                  note));
    }
    return out.toString();
  }

  private static String settings(Params params) {
    if (params.algorithm() == Algorithm.WINDOW) {
      double cap = params.number("max_stroke_ms");
      // As Python's describe: a stroke merged with a brief neighbour can last longer.
      String capText =
          cap != 0 ? "cut after " + Numbers.pythonG(cap) + " ms of drawing" : "not cut by time";
      if (params.flag("least_squares")) {
        double floorMs = Math.max(params.number("floor_ms"), params.number("min_duration_ms"));
        return "window, least squares: max error "
            + Numbers.pythonG(params.number("max_error"))
            + " grid units, strokes of "
            + Numbers.pythonG(floorMs)
            + " ms or more (the sleeve's floor), sent "
            + Numbers.pythonG(params.number("lookahead_ms"))
            + " ms after their end is drawn, "
            + capText;
      }
      return "window, chord: max error "
          + Numbers.pythonG(params.number("max_error"))
          + " grid units, every sample, "
          + capText;
    }
    return "angle: check every "
        + PyRepr.of(params.get("check_frames"))
        + " frames, max "
        + Numbers.pythonG(params.number("max_angle_deg"))
        + " deg, "
        + Numbers.pythonG(params.fps())
        + " fps";
  }

  private static String point(double x, double y) {
    return "(" + fixed(x, 3) + ", " + fixed(y, 3) + ")";
  }

  /** Python's {@code f"{value:.Nf}"}: the exact binary value rounded half to even. */
  static String fixed(double value, int decimals) {
    String text = new BigDecimal(value).setScale(decimals, RoundingMode.HALF_EVEN).toPlainString();
    boolean negative = value < 0 || (value == 0 && 1 / value < 0);
    return negative && !text.startsWith("-") ? "-" + text : text;
  }

}
