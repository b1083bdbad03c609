package feelmysign.processing;

import feelmysign.client.SleeveEvent;
import feelmysign.protocol.Stroke;
import feelmysign.testing.LiveSleeve;
import java.io.IOException;
import java.io.PrintWriter;
import java.lang.management.ManagementFactory;
import java.lang.management.MemoryMXBean;
import java.net.URL;
import java.net.URLClassLoader;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import java.util.Map;
import java.util.Random;
import java.util.concurrent.atomic.AtomicLong;
import javax.tools.JavaCompiler;
import javax.tools.ToolProvider;
import processing.core.PApplet;
import processing.core.PConstants;
import processing.event.MouseEvent;

/**
 * A long session: the examples ModernSketch (window simplifier, JSON v1, the preview of what the
 * sleeve played from its events) and PaperSketch (angle simplifier, the paper's text, the sent
 * vectors drawn) run as a user runs them, on Xvfb's screen, against a real broker and {@code
 * feelmysign sleeve --backend sim}. A scripted mouse draws path after path (1.5 s each, a sample
 * every frame, the shape varied), on one sketch then the other. Every minute it writes a CSV row:
 * the heap used after a full GC, the JVM's resident memory, draw() time per frame (p50, p95),
 * the frame interval's p95, strokes sent and played; at the end it prints the last five minutes
 * against the first five (after one minute of warm-up) as ratios.
 *
 * <p>{@code make java-soak} runs it ({@code SOAK_MINUTES=60} by default); it is no test: it
 * asserts nothing and times things. The CSV is written a row at a time, so a session stopped
 * early still has its minutes: {@code --summary CSV} summarises them.
 */
public final class SoakSketches {
  private static final String SLEEVE = "soak";
  /** The mouse's path: 1.5 s, one sample per 60 fps frame, then a pause before the next. */
  static final long PATH_MS = 1_500;
  static final long SAMPLE_MS = 16;
  static final long PAUSE_MS = 400;

  private SoakSketches() {}

  /** draw() time and frame interval of one sketch, per frame, for the minute being measured. */
  public static final class Probe {
    private final PApplet sketch;
    private FeelMySign library;
    private long preNs;
    private long lastPreNs;
    private double[] drawMs = new double[8192];
    private double[] intervalMs = new double[8192];
    private int draws;
    private int intervals;
    private Stroke lastSeen;
    final AtomicLong sent = new AtomicLong();

    Probe(PApplet sketch) {
      this.sketch = sketch;
    }

    public void pre() {
      long now = System.nanoTime();
      synchronized (this) {
        if (lastPreNs != 0) {
          intervalMs = put(intervalMs, intervals++, (now - lastPreNs) / 1e6);
        }
      }
      lastPreNs = now;
      preNs = now;
    }

    /** After the sketch's draw() and the library's draw hook: the frame's time, the strokes sent. */
    public void post() {
      long now = System.nanoTime();
      synchronized (this) {
        drawMs = put(drawMs, draws++, (now - preNs) / 1e6);
      }
      if (library == null) {
        library = libraryOf(sketch);
      }
      // The library keeps the latest strokes; those after the last one seen are new.
      List<Stroke> kept = library.sent();
      int seenAt = -1;
      for (int i = kept.size() - 1; i >= 0; i--) {
        if (kept.get(i) == lastSeen) {
          seenAt = i;
          break;
        }
      }
      sent.addAndGet(kept.size() - 1 - seenAt);
      if (!kept.isEmpty()) {
        lastSeen = kept.get(kept.size() - 1);
      }
    }

    private static double[] put(double[] values, int at, double value) {
      double[] out = at < values.length ? values : Arrays.copyOf(values, values.length * 2);
      out[at] = value;
      return out;
    }

    /** The minute's draw times and intervals, sorted; the next minute starts empty. */
    synchronized double[][] drain() {
      double[][] out = {Arrays.copyOf(drawMs, draws), Arrays.copyOf(intervalMs, intervals)};
      draws = 0;
      intervals = 0;
      Arrays.sort(out[0]);
      Arrays.sort(out[1]);
      return out;
    }
  }

  static FeelMySign libraryOf(PApplet sketch) {
    try {
      java.lang.reflect.Field field = sketch.getClass().getDeclaredField("sleeve");
      field.setAccessible(true);
      return (FeelMySign) field.get(sketch);
    } catch (ReflectiveOperationException error) {
      throw new IllegalStateException(error);
    }
  }

  static double percentile(double[] sorted, double p) {
    if (sorted.length == 0) {
      return Double.NaN;
    }
    return sorted[Math.min(sorted.length - 1, (int) Math.floor(p * sorted.length))];
  }

  /** A path of {@code PATH_MS}, shape by {@code kind}, inside a w x h canvas. */
  static List<double[]> path(int kind, Random random, int w, int h) {
    int samples = (int) (PATH_MS / SAMPLE_MS);
    double cx = w * (0.3 + 0.4 * random.nextDouble());
    double cy = h * (0.3 + 0.4 * random.nextDouble());
    double r = Math.min(w, h) * (0.15 + 0.15 * random.nextDouble());
    List<double[]> out = new ArrayList<>();
    double x = cx;
    double y = cy;
    double heading = random.nextDouble() * 2 * Math.PI;
    for (int i = 0; i <= samples; i++) {
      double u = (double) i / samples;
      switch (kind) {
        case 0 -> { // circle
          x = cx + r * Math.cos(2 * Math.PI * u);
          y = cy + r * Math.sin(2 * Math.PI * u);
        }
        case 1 -> { // square, corner by corner
          double side = u * 4;
          int k = Math.min(3, (int) side);
          double f = side - k;
          double[][] c = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}, {-1, -1}};
          x = cx + r * (c[k][0] + (c[k + 1][0] - c[k][0]) * f);
          y = cy + r * (c[k][1] + (c[k + 1][1] - c[k][1]) * f);
        }
        case 2 -> { // zigzag
          x = cx - r + 2 * r * u;
          y = cy + r * 0.6 * (((int) (u * 6)) % 2 == 0 ? (u * 6 % 1) : 1 - (u * 6 % 1));
        }
        case 3 -> { // spiral
          x = cx + r * u * Math.cos(6 * Math.PI * u);
          y = cy + r * u * Math.sin(6 * Math.PI * u);
        }
        default -> { // a wandering hand
          heading += (random.nextDouble() - 0.5) * 0.6;
          x = Math.max(5, Math.min(w - 5, x + 14 * Math.cos(heading)));
          y = Math.max(5, Math.min(h - 5, y + 14 * Math.sin(heading)));
        }
      }
      out.add(new double[] {x, y});
    }
    return out;
  }

  /** Compiles an example as the PDE would and starts it; its probe registered. */
  private static PApplet run(Path dir, String name, Map<String, String> constants, Probe[] probe)
      throws Exception {
    Path pde = Path.of("examples", name, name + ".pde");
    String source = PaperSketchIT.sketchSource(Files.readString(pde), name, constants);
    Path src = dir.resolve("sketch/" + name + ".java");
    Path classes = dir.resolve("classes");
    Files.createDirectories(src.getParent());
    Files.createDirectories(classes);
    Files.writeString(src, source);
    JavaCompiler javac = ToolProvider.getSystemJavaCompiler();
    int rc = javac.run(null, null, null, "-proc:none", "-d", classes.toString(),
        "-cp", System.getProperty("java.class.path"), src.toString());
    if (rc != 0) {
      throw new IllegalStateException("the example " + name + " does not compile");
    }
    URLClassLoader loader = new URLClassLoader(new URL[] {classes.toUri().toURL()},
        SoakSketches.class.getClassLoader());
    PApplet applet = (PApplet) loader.loadClass(name).getDeclaredConstructor().newInstance();
    probe[0] = new Probe(applet);
    applet.registerMethod("pre", probe[0]);
    applet.registerMethod("post", probe[0]);
    PApplet.runSketch(new String[] {"--location=0,0", name}, applet);
    LiveSleeve.waitFor(() -> applet.frameCount > 3, "frames drawn by " + name);
    FeelMySign library = libraryOf(applet);
    LiveSleeve.waitFor(library::connected, name + "'s connection to the broker");
    return applet;
  }

  private static long rssKb() {
    try {
      for (String line : Files.readAllLines(Path.of("/proc/self/status"))) {
        if (line.startsWith("VmRSS:")) {
          return Long.parseLong(line.replaceAll("\\D", ""));
        }
      }
    } catch (IOException unreadable) {
      // Not Linux: no RSS column.
    }
    return -1;
  }

  /**
   * {@code SoakSketches MINUTES [CSV]} runs a session; {@code SoakSketches --summary CSV} prints
   * the summary of a session's CSV so far (e.g. of a run stopped early).
   */
  public static void main(String[] args) throws Exception {
    if (args.length == 2 && args[0].equals("--summary")) {
      List<double[]> rows = new ArrayList<>();
      for (String line : Files.readAllLines(Path.of(args[1]))) {
        if (!line.isEmpty() && Character.isDigit(line.charAt(0))) {
          rows.add(Arrays.stream(line.split(",")).mapToDouble(Double::parseDouble).toArray());
        }
      }
      summary(rows);
      return;
    }
    double minutes = Double.parseDouble(args.length > 0 ? args[0] : "60");
    Path csv = Path.of(args.length > 1 ? args[1] : "target/soak.csv").toAbsolutePath();
    Path state = Files.createTempDirectory("feelmysign-soak");
    AtomicLong played = new AtomicLong();
    try (LiveSleeve live = LiveSleeve.start(state, SLEEVE, List.of(), List.of());
        LiveSleeve.Listening listener = new LiveSleeve.Listening() {
          @Override
          protected void heard(Object item) {
            if (item instanceof SleeveEvent e
                && (SleeveEvent.PLAYED.equals(e.type()) || SleeveEvent.ADJUSTED.equals(e.type()))) {
              played.incrementAndGet();
            }
            // Counted, not kept: the harness must not grow either.
            events.clear();
            statuses.clear();
          }
        }) {
      listenTo(live, listener);
      Map<String, String> login = Map.of("BROKER", live.mqttUrl(), "USER", live.senderUser(),
          "PASSWORD", live.senderPassword(), "SLEEVE", SLEEVE);
      Probe[] modernProbe = new Probe[1];
      Probe[] paperProbe = new Probe[1];
      PApplet modern = run(state, "ModernSketch", login, modernProbe);
      PApplet paper = run(state, "PaperSketch", login, paperProbe);
      PApplet[] sketches = {modern, paper};
      Probe[] probes = {modernProbe[0], paperProbe[0]};

      Thread mouse = new Thread(() -> drawForever(sketches), "scripted-mouse");
      mouse.setDaemon(true);
      mouse.start();

      MemoryMXBean memory = ManagementFactory.getMemoryMXBean();
      List<double[]> rows = new ArrayList<>();
      String header = "minute,heap_after_gc_kb,rss_kb,modern_draw_p50_ms,modern_draw_p95_ms,"
          + "modern_interval_p95_ms,paper_draw_p50_ms,paper_draw_p95_ms,paper_interval_p95_ms,"
          + "frames,strokes_sent,strokes_played";
      Files.createDirectories(csv.getParent());
      long startNs = System.nanoTime();
      try (PrintWriter out = new PrintWriter(Files.newBufferedWriter(csv))) {
        out.println(header);
        System.out.println(header);
        for (int minute = 1; minute <= Math.ceil(minutes); minute++) {
          long untilNs = startNs + (long) (Math.min(minute, minutes) * 60e9);
          while (System.nanoTime() < untilNs) {
            Thread.sleep(Math.max(1, (untilNs - System.nanoTime()) / 1_000_000));
          }
          double[][] m = probes[0].drain();
          double[][] p = probes[1].drain();
          System.gc();
          long heapKb = memory.getHeapMemoryUsage().getUsed() / 1024;
          double[] row = {minute, heapKb, rssKb(),
              percentile(m[0], 0.5), percentile(m[0], 0.95), percentile(m[1], 0.95),
              percentile(p[0], 0.5), percentile(p[0], 0.95), percentile(p[1], 0.95),
              m[0].length + p[0].length,
              probes[0].sent.get() + probes[1].sent.get(), played.get()};
          rows.add(row);
          StringBuilder line = new StringBuilder();
          for (int i = 0; i < row.length; i++) {
            line.append(i == 0 ? "" : ",").append(i == 0 || i == 1 || i == 2 || i >= 9
                ? String.valueOf((long) row[i]) : String.format("%.2f", row[i]));
          }
          out.println(line);
          out.flush();
          System.out.println(line);
        }
      }
      summary(rows);
      System.out.println("CSV: " + csv);
      for (PApplet sketch : sketches) {
        sketch.noLoop();
        sketch.dispose();
      }
    }
    System.exit(0);
  }

  private static void listenTo(LiveSleeve live, LiveSleeve.Listening listener) throws Exception {
    // LiveSleeve.listen() builds its own Listening; this one counts and forgets.
    java.lang.reflect.Field client = LiveSleeve.Listening.class.getDeclaredField("client");
    client.setAccessible(true);
    var built = live.client(live.senderPassword()).listener(listener).build();
    client.set(listener, built);
    built.connect();
  }

  /** Last five minutes against the first five after a minute of warm-up, as ratios. */
  static void summary(List<double[]> rows) {
    String[] names = {"heap after GC", "RSS", "ModernSketch draw p50", "ModernSketch draw p95",
        "ModernSketch interval p95", "PaperSketch draw p50", "PaperSketch draw p95",
        "PaperSketch interval p95"};
    int n = rows.size();
    if (n < 3) {
      System.out.println("too short for a summary (" + n + " minutes)");
      return;
    }
    int window = Math.min(5, (n - 1) / 2);
    List<double[]> first = rows.subList(1, 1 + window);
    List<double[]> last = rows.subList(n - window, n);
    System.out.printf("summary: minutes %d-%d against %d-%d (the last against the first)%n",
        (int) first.get(0)[0], (int) first.get(window - 1)[0], (int) last.get(0)[0],
        (int) last.get(window - 1)[0]);
    for (int c = 1; c <= 8; c++) {
      double a = mean(first, c);
      double b = mean(last, c);
      System.out.printf("  %-26s first %10.2f  last %10.2f  ratio %.3f%n", names[c - 1], a, b,
          b / a);
    }
    double[] end = rows.get(n - 1);
    double[] start = rows.get(0);
    System.out.printf("  strokes sent %d, played %d (minute 1: %d sent)%n", (long) end[10],
        (long) end[11], (long) start[10]);
  }

  private static double mean(List<double[]> rows, int column) {
    return rows.stream().mapToDouble(r -> r[column]).average().orElse(Double.NaN);
  }

  /** The scripted mouse: a path on one sketch, then the next on the other, until the JVM ends. */
  private static void drawForever(PApplet[] sketches) {
    Random random = new Random(18);
    try {
      for (long path = 0; ; path++) {
        PApplet sketch = sketches[(int) (path % sketches.length)];
        List<double[]> points = path((int) (path % 5), random, sketch.width, sketch.height);
        long nextMs = System.currentTimeMillis();
        for (int i = 0; i < points.size(); i++) {
          int action = i == 0 ? MouseEvent.PRESS
              : i == points.size() - 1 ? MouseEvent.RELEASE : MouseEvent.DRAG;
          double[] p = points.get(i);
          sketch.postEvent(new MouseEvent(null, System.currentTimeMillis(), action, 0,
              (int) Math.round(p[0]), (int) Math.round(p[1]), PConstants.LEFT, 1));
          nextMs += SAMPLE_MS;
          long waitMs = nextMs - System.currentTimeMillis();
          if (waitMs > 0) {
            Thread.sleep(waitMs);
          }
        }
        Thread.sleep(PAUSE_MS);
      }
    } catch (InterruptedException stopped) {
      Thread.currentThread().interrupt();
    }
  }
}
