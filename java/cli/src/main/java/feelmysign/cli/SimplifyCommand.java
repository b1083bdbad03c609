package feelmysign.cli;

import feelmysign.json.Numbers;
import feelmysign.json.PyDumps;
import feelmysign.json.PyRepr;
import feelmysign.simplify.Algorithm;
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

  /** A flag: its name, the parameter it sets (null for the others) and its kind. */
  private record Option(String flag, String dest, Kind kind, String metavar, String help) {}

  private enum Kind {
    FLOAT,
    INT,
    TRUE,
    FALSE,
    CHOICE
  }

  private static final List<Option> OPTIONS =
      List.of(
          new Option("--algorithm", "algorithm", Kind.CHOICE, "{angle,window}",
              "the simplifier: angle (the paper's) or window (error-bounded, cut at features);"
                  + " default: the recording's, else window"),
          new Option("--paper", "paper", Kind.TRUE, null,
              "the paper's settings: the angle simplifier at its appendix B.1 values"),
          new Option("--max-error", "max_error", Kind.FLOAT, "E",
              "window: farthest a drawn point may lie from its stroke, grid units"),
          new Option("--max-window", "max_window", Kind.INT, "N",
              "window: longest stroke in samples after its start (bounds the work)"),
          new Option("--max-stroke-ms", "max_stroke_ms", Kind.FLOAT, "MS",
              "window: longest stroke in ms of drawing; 0 = no limit"),
          new Option("--check-frames", "check_frames", Kind.INT, "N",
              "angle: frames between checks"),
          new Option("--max-angle-deg", "max_angle_deg", Kind.FLOAT, "A",
              "angle: largest turn that continues a line, degrees"),
          new Option("--frame-max", "frame_max", Kind.INT, "N",
              "angle: longest line in frames, 0 = no limit"),
          new Option("--fps", "fps", Kind.FLOAT, "F", "angle: frames per second of the drawing loop"),
          new Option("--no-recover", "recover", Kind.FALSE, null,
              "angle: start a new line at the pointer after a failed check, leaving gaps"),
          new Option("--min-duration-ms", "min_duration_ms", Kind.FLOAT, "D",
              "shortest stroke sent, ms"),
          new Option("--min-length", "min_length", Kind.FLOAT, "L",
              "shortest stroke sent, grid units"),
          new Option("--rows", "rows", Kind.INT, "R",
              "actuator rows (default: the recording's sleeve, else 3)"),
          new Option("--columns", "columns", Kind.INT, "C",
              "actuator columns (default: the recording's sleeve, else 4)"),
          new Option("--stretch", "stretch", Kind.TRUE, null,
              "stretch the canvas onto the grid as the paper did"),
          new Option("--json", "json", Kind.TRUE, null, "print the strokes as JSON"),
          new Option("--help", "help", Kind.TRUE, null, "show this help and exit"));

  static final String USAGE =
      "usage: "
          + PROG
          + " [-h] [--algorithm {angle,window}] [--paper] [--max-error E]\n"
          + "       [--max-window N] [--max-stroke-ms MS] [--check-frames N]\n"
          + "       [--max-angle-deg A] [--frame-max N] [--fps F] [--no-recover]\n"
          + "       [--min-duration-ms D] [--min-length L] [--rows R] [--columns C]\n"
          + "       [--stretch] [--json]\n"
          + "       RECORDING\n";

  static int run(String[] args, PrintStream out, PrintStream err) {
    Map<String, Object> given = parse(args);
    if (given.containsKey("help")) {
      out.print(USAGE);
      out.println();
      out.println("Run a recording through a simplifier, exactly as the drawing client would,");
      out.println("and show the strokes it sends and the ones it drops.");
      out.println();
      for (Option option : OPTIONS) {
        String name = option.flag() + (option.metavar() == null ? "" : " " + option.metavar());
        out.printf("  %-26s %s%n", name, option.help());
      }
      return 0;
    }
    String path = (String) given.get("recording");
    Recording recording = load(path);
    Algorithm algorithm = chosenAlgorithm(given, recording, path);
    checkUsage(given, algorithm);
    Params params = params(given, recording, algorithm);
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
    return new Main.UsageException(PROG, USAGE, message);
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
      if (arg.equals("-h")) {
        given.put("help", true);
        continue;
      }
      String name = arg;
      String explicit = null;
      int equals = arg.indexOf('=');
      if (arg.startsWith("--") && equals > 0) {
        name = arg.substring(0, equals);
        explicit = arg.substring(equals + 1);
      }
      Option option = find(name);
      if (option == null) {
        unrecognized.add(arg);
        continue;
      }
      switch (option.kind()) {
        case TRUE, FALSE -> {
          if (explicit != null) {
            throw usage(
                "argument " + option.flag() + ": ignored explicit argument " + PyRepr.of(explicit));
          }
          given.put(option.dest(), option.kind() == Kind.TRUE);
        }
        default -> {
          String value = explicit;
          if (value == null) {
            if (i + 1 >= args.length
                || (args[i + 1].startsWith("-")
                    && !args[i + 1].equals("-")
                    && !isNegativeNumber(args[i + 1]))) {
              throw usage("argument " + option.flag() + ": expected one argument");
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

  /** An option by its name or a unique prefix of it, as argparse allows. */
  private static Option find(String name) {
    if (!name.startsWith("--")) {
      return null;
    }
    List<Option> matches = new ArrayList<>();
    for (Option option : OPTIONS) {
      if (option.flag().equals(name)) {
        return option;
      }
      if (option.flag().startsWith(name)) {
        matches.add(option);
      }
    }
    if (matches.size() > 1) {
      List<String> flags = matches.stream().map(Option::flag).toList();
      throw usage("ambiguous option: " + name + " could match " + String.join(", ", flags));
    }
    return matches.isEmpty() ? null : matches.get(0);
  }

  private static Object convert(Option option, String value) {
    switch (option.kind()) {
      case CHOICE -> {
        if (Algorithm.named(value) == null) {
          throw usage(
              "argument "
                  + option.flag()
                  + ": invalid choice: "
                  + PyRepr.of(value)
                  + " (choose from 'angle', 'window')");
        }
        return value;
      }
      case INT -> {
        Long number = PythonNumbers.parseInt(value);
        if (number == null) {
          throw usage(
              "argument "
                  + option.flag()
                  + ": "
                  + PyRepr.of(value)
                  + " is not a whole decimal number; write it with the digits 0-9, e.g. 3");
        }
        return number;
      }
      default -> {
        Double number = PythonNumbers.parseFloat(value);
        if (number == null) {
          throw usage(
              "argument "
                  + option.flag()
                  + ": "
                  + PyRepr.of(value)
                  + " is not a decimal number; write it with the digits 0-9, e.g. 0.25, 12 or "
                  + "2e-3");
        }
        return number;
      }
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
        String flag = name.equals("recover") ? "--no-recover" : "--" + name.replace('_', '-');
        throw usage(flag + " only applies to --algorithm " + only.getValue().wireName());
      }
    }
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
      String capText = cap != 0 ? Numbers.pythonG(cap) + " ms" : "no limit";
      return "window: max error "
          + Numbers.pythonG(params.number("max_error"))
          + " grid units, every sample, longest stroke "
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
