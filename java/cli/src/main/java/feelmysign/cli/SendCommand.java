package feelmysign.cli;

import feelmysign.client.SleeveClient;
import feelmysign.client.SleeveFloor;
import feelmysign.client.WearerState;
import feelmysign.json.Numbers;
import feelmysign.json.PyJson;
import feelmysign.protocol.Layout;
import feelmysign.protocol.ParseResult;
import feelmysign.protocol.Protocol;
import feelmysign.protocol.Stroke;
import feelmysign.protocol.WireFormat;
import feelmysign.shapes.Shapes;
import feelmysign.simplify.Params;
import feelmysign.simplify.PathSegment;
import feelmysign.simplify.Recording;
import feelmysign.simplify.Simplify;
import feelmysign.client.BrokerUrl;
import feelmysign.client.ConnectFailure;
import java.io.IOException;
import java.io.PrintStream;
import java.io.UncheckedIOException;
import java.net.ConnectException;
import java.net.InetSocketAddress;
import java.net.Socket;
import java.net.UnknownHostException;
import java.nio.file.Files;
import java.nio.file.NoSuchFileException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Set;

/**
 * {@code feelmysign-java send}: strokes, a shape or a recording to a sleeve, as {@code
 * feelmysign send} does (its flags where they apply): every stroke checked first, one drawing,
 * QoS 1, and the command returns once the broker has acknowledged every stroke (exit 0), or
 * says why not (exit 1). A sleeve its wearer paused, or asked not to be disturbed, gets nothing:
 * one line says so and what to do (exit 3), as the Python CLI's. Strokes go out at the pace they play ({@code --pace realtime}, the
 * default, as the reference's: each stroke once the one before would have finished), so a
 * second send right after it is not queued behind it and refused as late, and no stroke arrives
 * ahead of its drawing (the sleeve would play it faster to catch up, as {@code --pace burst}
 * asks).
 */
final class SendCommand {
  private SendCommand() {}

  static final String PROG = Main.PROG + " send";
  static final String USAGE =
      "usage: " + PROG + " [-h] [--shape {circle,square,triangle,star,heart,line}]\n"
          + "       [--segments N] [--duration-ms D] [--margin M] [--recording FILE [--paper]]\n"
          + "       [--intensity A] [--legacy] [--legacy-topic TOPIC]\n"
          + "       [--pace {realtime,burst}] [--timeout-s S]\n"
          + "       [--broker URL] [--id ID] [--username U] [--password P]\n"
          + "       [--credentials FILE] [--ca FILE] [--ca-fingerprint SHA256]\n"
          + "       [--rows R] [--columns C] [--spacing-cm S] [STROKE ...]";
  static final String HELP = USAGE + "\n\n"
      + "Send strokes (startX,startY,endX,endY,duration in grid units and ms), a shape of the\n"
      + "study's library (--shape, --segments), or a recording cut by the simplifier\n"
      + "(--recording; the window simplifier, --paper for the paper's angle one) to a sleeve,\n"
      + "and wait until the broker has them. --pace realtime (the default) sends each stroke\n"
      + "when the previous one would have finished playing, like a person drawing, so the\n"
      + "command lasts as long as the drawing plays; --pace burst sends them all at once, and\n"
      + "the sleeve then plays every stroke after the first faster, down to its floor, to catch\n"
      + "up with a drawing that arrived ahead of it. Broker settings: the option, else\n"
      + "--credentials (the credentials.json of 'feelmysign broker'), else the default\n"
      + "(mqtt://127.0.0.1:1883, sleeve1). The grid: the paper's sleeve, 3 x 4, 3 cm apart.\n"
      + "When the sleeve's status advertises a floor, a recording is cut keeping to it (the\n"
      + "window simplifier merges what is briefer; a wearer's limits raise the minimums), and\n"
      + "one line on stderr says how many strokes are below it.\n";

  // The faintest intensity sent (the reference's and the page's): at 0 the sleeve would play,
  // and report as played, a stroke no one feels.
  static final double MIN_INTENSITY = 0.01;

  // The options that take a value, by the kind of value; --paper and --legacy take none.
  private static final Set<String> WHOLE = Set.of("--segments", "--rows", "--columns");
  private static final Set<String> DECIMAL =
      Set.of("--duration-ms", "--margin", "--intensity", "--timeout-s", "--spacing-cm");
  private static final Set<String> TEXT =
      Set.of("--shape", "--recording", "--legacy-topic", "--pace", "--broker", "--id",
          "--username", "--password", "--credentials", "--ca", "--ca-fingerprint");

  /**
   * The options given, by flag: a String, a Long, a Double, or TRUE for --paper and --legacy,
   * each converted where it stands, as the reference's parser does; the rest, the strokes, into
   * {@code strokeArgs}. Null for --help.
   */
  private static Map<String, Object> parse(String[] args, List<String> strokeArgs) {
    Map<String, Object> given = new HashMap<>();
    for (int i = 0; i < args.length; i++) {
      String a = args[i];
      if (a.equals("-h") || a.equals("--help")) {
        return null;
      } else if (a.equals("--paper") || a.equals("--legacy")) {
        given.put(a, Boolean.TRUE);
      } else if (WHOLE.contains(a)) {
        given.put(a, integer(value(args, ++i, a), a));
      } else if (DECIMAL.contains(a)) {
        String text = value(args, ++i, a);
        double number = number(text, a);
        if (a.equals("--intensity") && !(number >= MIN_INTENSITY && number <= 1)) {
          throw new Main.UsageException(PROG, "argument --intensity: " + text
              + " is out of range; give a number from 0.01 to 1"
              + " (at 0 the sleeve would play strokes no one feels)");
        }
        given.put(a, number);
      } else if (TEXT.contains(a)) {
        given.put(a, value(args, ++i, a));
      } else if (a.startsWith("--")) {
        throw new Main.UsageException(PROG, "unrecognized arguments: " + a);
      } else {
        strokeArgs.add(a);
      }
    }
    Object pace = given.get("--pace");
    if (pace != null && !pace.equals("realtime") && !pace.equals("burst")) {
      throw new Main.UsageException(PROG, "argument --pace: invalid choice: '" + pace
          + "' (choose from 'realtime', 'burst')");
    }
    return given;
  }

  static int run(String[] args, PrintStream out, PrintStream err) {
    List<String> strokeArgs = new ArrayList<>();
    Map<String, Object> given = parse(args, strokeArgs);
    if (given == null) {
      out.print(HELP);
      return 0;
    }
    String shape = (String) given.get("--shape");
    String recording = (String) given.get("--recording");
    double timeoutS = (Double) given.getOrDefault("--timeout-s", 10.0);
    int rows = ((Long) given.getOrDefault("--rows", 3L)).intValue();
    int columns = ((Long) given.getOrDefault("--columns", 4L)).intValue();
    int sources = (shape != null ? 1 : 0) + (recording != null ? 1 : 0)
        + (strokeArgs.isEmpty() ? 0 : 1);
    if (sources != 1) {
      throw new Main.UsageException(PROG,
          "give one of: STROKE ..., --shape NAME or --recording FILE");
    }
    if (!(timeoutS > 0 && Double.isFinite(timeoutS))) {
      throw new IllegalArgumentException(
          "--timeout-s = " + timeoutS + " is not allowed; it must be a number of seconds above 0");
    }
    Layout layout = new Layout(rows, columns, Layout.PAPER.maxStrokeDurationMs());

    List<Stroke> strokes = strokes(given, strokeArgs, layout, null, null);

    // Broker settings: option, else credentials file, else default.
    if (given.get("--credentials") instanceof String credentials) {
      Map<String, Object> document = readCredentials(Path.of(credentials));
      if (document.get("mqtt_url") instanceof String url) {
        given.putIfAbsent("--broker", url);
      }
      if (document.get("sleeve") instanceof Map<?, ?> sleeve
          && sleeve.get("id") instanceof String id) {
        given.putIfAbsent("--id", id);
      }
      if (document.get("sender") instanceof Map<?, ?> sender) {
        if (sender.get("username") instanceof String u) {
          given.putIfAbsent("--username", u);
        }
        if (sender.get("password") instanceof String p) {
          given.putIfAbsent("--password", p);
        }
      }
      if (!given.containsKey("--ca") && document.get("ca_fingerprint") instanceof String f) {
        given.putIfAbsent("--ca-fingerprint", f);
      }
    }
    String url = (String) given.getOrDefault("--broker", "mqtt://127.0.0.1:1883");
    String sleeveId = (String) given.getOrDefault("--id", "sleeve1");
    String username = (String) given.get("--username");
    SleeveClient.Builder builder = SleeveClient.builder(url).sleeveId(sleeveId);
    if (username != null) {
      builder.login(username, (String) given.getOrDefault("--password", ""));
    }
    boolean legacy = given.containsKey("--legacy");
    if (legacy) {
      builder.format(WireFormat.LEGACY);
      if (given.get("--legacy-topic") instanceof String topic) {
        builder.legacyTopic(topic);
      }
    }
    if (given.get("--ca") instanceof String ca) {
      builder.caCertificate(Path.of(ca));
    }
    if (given.get("--ca-fingerprint") instanceof String fingerprint) {
      builder.caFingerprint(fingerprint);
    }
    String[] lastSaid = {"no answer"};
    // The sleeve's retained status, the first that comes: the wearer's choice in it.
    java.util.concurrent.CompletableFuture<WearerState> wearer =
        new java.util.concurrent.CompletableFuture<>();
    builder.listener(new SleeveClient.Listener() {
      @Override
      public void broker(SleeveClient.State state, String detail) {
        synchronized (lastSaid) {
          lastSaid[0] = detail;
        }
      }

      @Override
      public void status(String payload) {
        if (SleeveClient.onlineWearer(payload) == null) {
          wearer.complete(WearerState.NONE); // offline, cleared or not understood: no hold known
        }
      }

      @Override
      public void wearer(WearerState state) {
        wearer.complete(state);
      }

      @Override
      public void noSleeve(String sentence) {
        // Not said: the command's output stays the Python CLI's, which has no such line.
      }

      @Override
      public void floorIgnored(String sentence) {
        err.println(Character.toUpperCase(sentence.charAt(0)) + sentence.substring(1));
      }
    });
    refuseWhenNobodyListens(url);
    Object pace = given.get("--pace");
    boolean realtime = pace == null || pace.equals("realtime");
    try (SleeveClient client = builder.build()) {
      client.connect();
      // A paused sleeve, or one in "do not disturb", refuses every stroke: nothing is sent into
      // refusals. The retained status comes at once if the sleeve ever reported; else none.
      WearerState said = awaitWearer(wearer);
      long nowMs = System.currentTimeMillis();
      if (!legacy && said.holds(nowMs)) {
        err.println("Error: " + said.holdSentence(sleeveId, nowMs, java.time.ZoneId.systemDefault()));
        return WEARER_HOLD_EXIT;
      }
      // The status that said the wearer's choice said the sleeve's floor too, if it has one.
      SleeveFloor floor = client.floor();
      if (recording != null && floor != null) {
        strokes = strokes(given, strokeArgs, layout, floor, err);
      }
      sayFloor(floor, strokes, err);
      client.newDrawing();
      if (realtime) {
        // Each stroke when the one before would have finished playing, once the broker has the
        // one before: the sleeve's queue stays short, as when a person draws.
        long startNs = System.nanoTime();
        double offsetMs = 0;
        for (Stroke s : strokes) {
          sleepUntil(startNs + (long) (offsetMs * 1e6));
          client.send(s);
          if (!awaitBroker(client, timeoutS)) {
            break;
          }
          offsetMs += s.durationMs();
        }
      } else {
        for (Stroke s : strokes) {
          client.send(s);
        }
        awaitBroker(client, timeoutS);
      }
      if (client.loginRefused()) {
        err.println("Error: the broker refused "
            + (username == null ? "a login without a user name" : "the login of '" + username + "'")
            + ": give --username and --password, or --credentials FILE, the credentials.json"
            + " that 'feelmysign broker' writes in its state directory (its sender's login);"
            + " nothing was sent");
        return 1;
      }
      if (client.unsent() > 0) {
        synchronized (lastSaid) {
          err.println("Error: " + client.unsent() + " of " + strokes.size()
              + " strokes did not reach the broker within " + timeoutS + " s: " + lastSaid[0]);
        }
        return 1;
      }
      out.println("Sent " + strokes.size() + " stroke" + (strokes.size() == 1 ? "" : "s")
          + (legacy ? " as legacy text" : " to sleeve '" + sleeveId + "' (drawing " + client.drawing() + ")") + "; the broker has them.");
      return 0;
    }
  }

  /**
   * The strokes to send, each checked as the sleeve will check it: the STROKE arguments, the
   * shape, or the recording cut by the simplifier keeping to {@code floor} (null: none known).
   * {@code said} gets the line of a floor that raised the simplifier's minimums (null: silent).
   */
  private static List<Stroke> strokes(Map<String, Object> given, List<String> strokeArgs,
      Layout layout, SleeveFloor floor, PrintStream said) {
    String shape = (String) given.get("--shape");
    String recording = (String) given.get("--recording");
    Double intensity = (Double) given.get("--intensity");
    int rows = layout.rows();
    int columns = layout.columns();
    List<Stroke> strokes = new ArrayList<>();
    if (shape != null) {
      Long segments = (Long) given.get("--segments");
      strokes.addAll(Shapes.strokes(shape, rows, columns,
          (Double) given.getOrDefault("--spacing-cm", 3.0), layout.maxStrokeDurationMs(),
          segments == null ? null : segments.intValue(), (Double) given.get("--duration-ms"),
          (Double) given.getOrDefault("--margin", 0.0)));
    } else if (recording != null) {
      strokes.addAll(fromRecording(
          Path.of(recording), given.containsKey("--paper"), rows, columns, floor, said));
    } else {
      for (String text : strokeArgs) {
        strokes.add(parseStroke(text));
      }
    }
    if (strokes.isEmpty()) {
      throw new IllegalArgumentException(floor == null
          ? "nothing to send: the recording gave no strokes"
          : "nothing to send: the recording gave no strokes at or above the sleeve's floor ("
              + Numbers.pythonG(floor.minDurationMs()) + " ms and "
              + Numbers.pythonG(floor.minLength()) + " grid units"
              + (floor.hasWearer() ? ", wearer " + floor.wearer() + "'s limits" : "")
              + "); draw it larger or slower");
    }
    if (intensity != null) {
      List<Stroke> with = new ArrayList<>();
      for (Stroke s : strokes) {
        with.add(new Stroke(s.startX(), s.startY(), s.endX(), s.endY(), s.durationMs(),
            intensity, null, null, null));
      }
      strokes = with;
    }
    // Every stroke checked as the sleeve will, before anything is sent.
    for (int i = 0; i < strokes.size(); i++) {
      if (Protocol.validateStroke(strokes.get(i), layout) instanceof ParseResult.Rejected r) {
        String why = r.message().endsWith(".") ? r.message() : r.message() + ".";
        throw new IllegalArgumentException("stroke " + (i + 1) + ": " + why + " Nothing was sent.");
      }
    }
    return strokes;
  }

  /** How long the retained status may take to come after connecting (the Python CLI's too). */
  static final double STATUS_WAIT_S = 2.5;

  /** The exit status when the wearer's choice holds the drawing (the Python CLI's too). */
  static final int WEARER_HOLD_EXIT = 3;

  private static WearerState awaitWearer(java.util.concurrent.CompletableFuture<WearerState> said) {
    try {
      return said.get((long) (STATUS_WAIT_S * 1000), java.util.concurrent.TimeUnit.MILLISECONDS);
    } catch (java.util.concurrent.TimeoutException | java.util.concurrent.ExecutionException e) {
      return WearerState.NONE;
    } catch (InterruptedException e) {
      Thread.currentThread().interrupt();
      return WearerState.NONE;
    }
  }

  /** Waits until the broker has every stroke sent; false when it refused or timed out. */
  private static boolean awaitBroker(SleeveClient client, double timeoutS) {
    long deadline = System.nanoTime() + (long) (timeoutS * 1e9);
    while (client.unsent() > 0 && !client.loginRefused() && System.nanoTime() < deadline) {
      try {
        Thread.sleep(5);
      } catch (InterruptedException stop) {
        Thread.currentThread().interrupt();
        return false;
      }
    }
    return client.unsent() == 0;
  }

  private static void sleepUntil(long dueNs) {
    long waitNs;
    while ((waitNs = dueNs - System.nanoTime()) > 0) {
      try {
        Thread.sleep(waitNs / 1_000_000, (int) (waitNs % 1_000_000));
      } catch (InterruptedException stop) {
        Thread.currentThread().interrupt();
        return;
      }
    }
  }

  private static List<Stroke> fromRecording(
      Path file, boolean paper, int rows, int columns, SleeveFloor floor, PrintStream said) {
    byte[] data;
    try {
      data = Files.readAllBytes(file);
    } catch (IOException error) {
      throw new UncheckedIOException("cannot read the recording " + file + ": " + error.getMessage(),
          error);
    }
    Recording rec = Recording.parse(Recording.decode(data, file.toString()), file.toString());
    Params params = (paper ? Params.angle() : Params.window())
        .with("canvas_width_px", rec.widthPx()).with("canvas_height_px", rec.heightPx())
        .with("rows", rec.rows() == null ? rows : rec.rows())
        .with("columns", rec.columns() == null ? columns : rec.columns());
    if (floor != null) {
      // As feelmysign replay --send keeps to it (docs/protocol.md, floor).
      String note = floor.raisedNote(params);
      if (note != null && said != null) {
        said.println(note);
      }
      params = floor.applyTo(params);
    }
    List<Stroke> strokes = new ArrayList<>();
    for (PathSegment p : Simplify.paths(params, rec.paths())) {
      var s = p.segment();
      if (s.sent()) {
        strokes.add(new Stroke(s.startX(), s.startY(), s.endX(), s.endY(), s.durationMs()));
      }
    }
    return strokes;
  }

  /**
   * One line on stderr, as {@code feelmysign send} says it: the floor the sleeve advertises and
   * how many of the strokes are below it; said when some are, or when the floor is a wearer's
   * measured limits, not before every send.
   */
  static void sayFloor(SleeveFloor floor, List<Stroke> strokes, PrintStream err) {
    if (floor == null) {
      return;
    }
    long below = strokes.stream()
        .filter(s -> s.durationMs() < floor.minDurationMs()
            || Math.hypot(s.endX() - s.startX(), s.endY() - s.startY()) < floor.minLength())
        .count();
    if (below == 0 && !floor.hasWearer()) {
      return;
    }
    String whose = floor.hasWearer() ? " with wearer " + floor.wearer() + "'s limits" : "";
    // The sleeve slows only what its motors cannot play; a wearer's limits are kept by senders,
    // so below them a stroke is played as sent, and may not be felt.
    String why = floor.hasWearer()
        ? "sent as given: the wearer may not feel a briefer or shorter one"
        : "the sleeve slows a briefer one; a shorter one may not be felt";
    String verdict = below > 0
        ? below + " of the " + strokes.size() + " strokes are below it (" + why + ")"
        : "every stroke is at or above it";
    err.println("The sleeve's floor" + whose + ": strokes of at least "
        + Numbers.pythonG(floor.minDurationMs()) + " ms and " + Numbers.pythonG(floor.minLength())
        + " grid units; " + verdict + ".");
  }

  private static Stroke parseStroke(String text) {
    String[] parts = text.split(",", -1);
    if (parts.length != 5) {
      throw new IllegalArgumentException("STROKE " + text
          + " is not allowed; it must be startX,startY,endX,endY,duration (grid units, ms)");
    }
    double[] v = new double[5];
    for (int i = 0; i < 5; i++) {
      try {
        v[i] = Double.parseDouble(parts[i].strip());
      } catch (NumberFormatException notANumber) {
        throw new IllegalArgumentException("STROKE " + text
            + " is not allowed; it must be startX,startY,endX,endY,duration (grid units, ms)");
      }
    }
    return new Stroke(v[0], v[1], v[2], v[3], v[4]);
  }

  /**
   * Nothing listening at the broker's address is said at once, as {@code feelmysign send} says
   * it, rather than after {@code --timeout-s} of retries. Anything else (no answer, a slow
   * network) is left to the client, which retries until the timeout.
   */
  private static void refuseWhenNobodyListens(String url) {
    BrokerUrl where;
    try {
      where = BrokerUrl.parse(url);
    } catch (RuntimeException bad) {
      return; // the client says what is wrong with the URL
    }
    try (Socket probe = new Socket()) {
      probe.connect(new InetSocketAddress(where.host(), where.port()), 2000);
    } catch (ConnectException refused) {
      throw new IllegalArgumentException(ConnectFailure.refused(url, "--broker URL"));
    } catch (UnknownHostException unknown) {
      throw new IllegalArgumentException(
          ConnectFailure.unknownHost(url, where.host(), "--broker"));
    } catch (IOException other) {
      // No answer yet: the client keeps trying until --timeout-s.
    }
  }


  /** A credentials.json of 'feelmysign broker', checked as the reference checks it. */
  @SuppressWarnings("unchecked")
  private static Map<String, Object> readCredentials(Path file) {
    Object document;
    try {
      document = PyJson.loads(Files.readString(file));
    } catch (NoSuchFileException absent) {
      throw new IllegalArgumentException("No credentials file at " + file + "; start the broker"
          + " first ('feelmysign broker') or pass the file it wrote (STATE_DIR/credentials.json,"
          + " or STATE_DIR/sleeve-credentials.json for a sleeve).");
    } catch (IOException | RuntimeException unreadable) {
      throw badCredentials(file, "it cannot be read as JSON (" + unreadable.getMessage() + ")");
    }
    if (document instanceof Map<?, ?> map && !map.containsKey("sender")
        && map.containsKey("sleeve")) {
      throw badCredentials(file, "it holds only a sleeve's login (a sleeve-credentials.json); to"
          + " send, use the broker's credentials.json");
    }
    if (!(document instanceof Map<?, ?> map
        && map.get("mqtt_url") instanceof String
        && map.get("ws_url") instanceof String
        && map.get("sleeve") instanceof Map<?, ?> sleeve
        && sleeve.get("id") instanceof String
        && sleeve.get("username") instanceof String
        && sleeve.get("password") instanceof String
        && map.get("sender") instanceof Map<?, ?> sender
        && sender.get("username") instanceof String
        && sender.get("password") instanceof String)) {
      throw badCredentials(file,
          "it lacks mqtt_url, ws_url, sleeve{id, username, password} or sender{...}");
    }
    return (Map<String, Object>) map;
  }

  private static IllegalArgumentException badCredentials(Path file, String problem) {
    return new IllegalArgumentException("The credentials file " + file + " is not usable: "
        + problem + ". Fix it, or delete it to have the broker generate new passwords (every"
        + " sleeve and sender must then use the new file).");
  }

  private static String value(String[] args, int i, String flag) {
    if (i >= args.length) {
      throw new Main.UsageException(PROG, "argument " + flag + ": expected one argument");
    }
    return args[i];
  }

  private static double number(String text, String flag) {
    try {
      return Double.parseDouble(text);
    } catch (NumberFormatException e) {
      throw new Main.UsageException(PROG,
          "argument " + flag + ": invalid float value: '" + text + "'");
    }
  }

  private static long integer(String text, String flag) {
    try {
      return Long.parseLong(text);
    } catch (NumberFormatException e) {
      throw new Main.UsageException(PROG,
          "argument " + flag + ": invalid int value: '" + text + "'");
    }
  }

}
