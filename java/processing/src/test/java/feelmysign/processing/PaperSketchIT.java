package feelmysign.processing;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import feelmysign.client.SleeveClient;
import feelmysign.client.SleeveEvent;
import feelmysign.json.PyJson;
import feelmysign.protocol.Protocol;
import feelmysign.protocol.Stroke;
import java.awt.Rectangle;
import java.awt.Robot;
import java.io.BufferedReader;
import java.io.File;
import java.io.IOException;
import java.io.InputStreamReader;
import java.net.URL;
import java.net.URLClassLoader;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.concurrent.TimeUnit;
import java.util.function.BooleanSupplier;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import javax.imageio.ImageIO;
import javax.tools.JavaCompiler;
import javax.tools.ToolProvider;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;
import processing.core.PApplet;
import processing.core.PConstants;
import processing.event.MouseEvent;

/**
 * The paper's sketch example (examples/PaperSketch) as a user runs it, on Xvfb's screen, with
 * Processing's core from Maven Central: a scripted mouse draws a square; the strokes it sends
 * are the legacy text {@code feelmysign simplify --paper} computes from the same mouse path,
 * and a real {@code feelmysign sleeve --backend sim} plays them (played events come back).
 * make java-test runs it under xvfb-run; a screenshot is left in target/.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class PaperSketchIT {
  private static final long WAIT_S = 60; // generous: the machine may be busy
  private static final String SLEEVE = "sketch-test";
  static final Path SCREENSHOT = Path.of("target/paper-sketch-under-xvfb.png").toAbsolutePath();

  private Path state;
  private Path repository;
  private Process broker;
  private Process sleeve;
  private Map<String, Object> credentials;
  private PApplet sketch;

  private static Path repository() {
    for (Path dir = Path.of("").toAbsolutePath(); dir != null; dir = dir.getParent()) {
      if (Files.isDirectory(dir.resolve("testdata")) && Files.isDirectory(dir.resolve("python"))) {
        return dir;
      }
    }
    throw new IllegalStateException("not inside the feelmysign repository");
  }

  @BeforeAll
  void startBrokerAndSleeve(@TempDir Path dir) throws Exception {
    if (System.getenv("DISPLAY") == null) {
      fail("no X display: run 'make java-test', which starts Xvfb (xvfb-run) for this test");
    }
    state = dir;
    repository = repository();
    Path feelmysign = repository.resolve(".venv/bin/feelmysign");
    broker = new ProcessBuilder(feelmysign.toString(), "broker", "--state-dir", state.toString(),
            "--port", "0", "--ws-port", "0", "--sleeve-id", SLEEVE)
        .redirectErrorStream(true).start();
    BufferedReader out = new BufferedReader(
        new InputStreamReader(broker.getInputStream(), StandardCharsets.UTF_8));
    StringBuilder said = new StringBuilder();
    for (String line; (line = out.readLine()) != null; ) {
      said.append(line).append('\n');
      if (line.startsWith("Ready.")) {
        break;
      }
    }
    assertTrue(said.toString().contains("Ready."), "feelmysign broker failed:\n" + said);
    Thread drain = new Thread(() -> {
      try {
        out.lines().forEach(line -> {});
      } catch (java.io.UncheckedIOException closed) {
        // The broker stopped.
      }
    }, "broker-output");
    drain.setDaemon(true);
    drain.start();
    Path file = state.resolve("credentials.json");
    @SuppressWarnings("unchecked")
    Map<String, Object> document = (Map<String, Object>) PyJson.loads(Files.readString(file));
    credentials = document;
    // The sleeve with its legacy topic (deviceOne/line), as the paper's sketch sends.
    sleeve = new ProcessBuilder(feelmysign.toString(), "sleeve", "--credentials", file.toString(),
            "--backend", "sim", "--log-level", "warning")
        .redirectErrorStream(true).redirectOutput(state.resolve("sleeve.log").toFile()).start();
  }

  @AfterAll
  void stopThem() throws InterruptedException {
    if (sketch != null) {
      sketch.noLoop();
      sketch.getSurface().setVisible(false);
      sketch.dispose(); // the library's dispose hook closes its client (exit() would end the JVM)
    }
    for (Process process : new Process[] {sleeve, broker}) {
      if (process != null) {
        process.destroy();
        if (!process.waitFor(WAIT_S, TimeUnit.SECONDS)) {
          process.destroyForcibly();
        }
      }
    }
  }

  /** The example as the PDE's preprocessor makes it: a PApplet, size() in settings(). */
  static String sketchSource(String pde, String className, Map<String, String> constants) {
    StringBuilder imports = new StringBuilder("import processing.core.*;\nimport processing.event.*;\n");
    StringBuilder body = new StringBuilder();
    String size = null;
    for (String line : pde.split("\n", -1)) {
      if (line.startsWith("import ")) {
        imports.append(line).append('\n');
        continue;
      }
      Matcher sizeCall = Pattern.compile("^\\s*(size\\([^)]*\\);)\\s*$").matcher(line);
      if (sizeCall.matches()) {
        size = sizeCall.group(1);
        continue;
      }
      Matcher constant = Pattern.compile("^String (\\w+) = \"[^\"]*\";(.*)$").matcher(line);
      if (constant.matches() && constants.containsKey(constant.group(1))) {
        line = "String " + constant.group(1) + " = \"" + constants.get(constant.group(1)) + "\";";
      }
      body.append(line.replaceAll("^void (\\w+)\\(", "public void $1(")).append('\n');
    }
    assertTrue(size != null, "the example has no size() call");
    return imports + "public class " + className + " extends PApplet {\n"
        + "public void settings() { " + size + " }\n" + body + "}\n";
  }

  /** Compiles an example as the PDE would; returns where its class is. */
  private Path compile(String name, Map<String, String> constants) throws Exception {
    Path pde = Path.of("examples", name, name + ".pde");
    String source = sketchSource(Files.readString(pde), name, constants);
    Path src = state.resolve("sketch/" + name + ".java");
    Path classes = state.resolve("classes");
    Files.createDirectories(src.getParent());
    Files.createDirectories(classes);
    Files.writeString(src, source);
    JavaCompiler javac = ToolProvider.getSystemJavaCompiler();
    int rc = javac.run(null, null, null, "-proc:none", "-d", classes.toString(),
        "-cp", System.getProperty("java.class.path"), src.toString());
    assertEquals(0, rc, "the example " + name + " does not compile:\n" + source);
    return classes;
  }

  @Test
  void everyExampleCompilesAgainstTheLibrary() throws Exception {
    for (String name : List.of("PaperSketch", "ModernSketch", "StudyShape")) {
      assertTrue(Files.exists(compile(name, Map.of()).resolve(name + ".class")), name);
    }
  }

  private PApplet compileAndRun(String name, Map<String, String> constants) throws Exception {
    Path classes = compile(name, constants);
    URLClassLoader loader = new URLClassLoader(new URL[] {classes.toUri().toURL()},
        getClass().getClassLoader());
    PApplet applet = (PApplet) loader.loadClass(name).getDeclaredConstructor().newInstance();
    PApplet.runSketch(new String[] {"--location=0,0", name}, applet);
    return applet;
  }

  private static void waitFor(BooleanSupplier condition, String what) throws InterruptedException {
    long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(WAIT_S);
    while (!condition.getAsBoolean()) {
      if (System.nanoTime() > deadline) {
        fail("no " + what + " within " + WAIT_S + " s");
      }
      Thread.sleep(20);
    }
  }

  /** A square drawn by hand: press, drags every 16 ms at about 1.5 px/ms, release. */
  static List<long[]> squarePath() {
    int[][] corners = {{400, 200}, {1500, 200}, {1500, 900}, {400, 900}, {400, 200}};
    List<long[]> path = new ArrayList<>(); // millis, x, y
    long t = 1_000;
    path.add(new long[] {t, corners[0][0], corners[0][1]});
    for (int c = 1; c < corners.length; c++) {
      int[] a = corners[c - 1];
      int[] b = corners[c];
      int steps = (int) Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / 24.0);
      for (int k = 1; k <= steps; k++) {
        t += 16;
        path.add(new long[] {t, Math.round(a[0] + (b[0] - a[0]) * (double) k / steps),
            Math.round(a[1] + (b[1] - a[1]) * (double) k / steps)});
      }
    }
    return path;
  }

  @Test
  void aSquareDrawnWithTheMouseIsSentAsSimplifyPaperSaysAndPlayed() throws Exception {
    @SuppressWarnings("unchecked")
    Map<String, Object> sender = (Map<String, Object>) credentials.get("sender");
    // The sleeve's events, heard as any other sender hears them.
    List<SleeveEvent> heard = new CopyOnWriteArrayList<>();
    List<String> statuses = new CopyOnWriteArrayList<>();
    SleeveClient listener = SleeveClient.builder((String) credentials.get("mqtt_url"))
        .login((String) sender.get("username"), (String) sender.get("password"))
        .sleeveId(SLEEVE)
        .listener(new SleeveClient.Listener() {
          @Override
          public void event(SleeveEvent event) {
            heard.add(event);
          }

          @Override
          public void status(String payload) {
            statuses.add(payload);
          }
        })
        .build();
    listener.connect();
    try {
      sketch = compileAndRun("PaperSketch", Map.of(
          "BROKER", (String) credentials.get("mqtt_url"),
          "USER", (String) sender.get("username"),
          "PASSWORD", (String) sender.get("password"),
          "SLEEVE", SLEEVE));
      waitFor(() -> sketch.frameCount > 3, "frames drawn by the sketch");
      java.lang.reflect.Field field = sketch.getClass().getDeclaredField("sleeve");
      field.setAccessible(true); // a sketch's fields are package-private, as the PDE makes them
      FeelMySign library = (FeelMySign) field.get(sketch);
      // The sleeve's retained status: the listener's subscriptions are in place, the sleeve is up.
      waitFor(() -> library.connected() && statuses.stream().anyMatch(p -> !p.isEmpty()),
          "connection to the broker and the sleeve's status");

      List<long[]> path = squarePath();
      for (int i = 0; i < path.size(); i++) {
        long[] p = path.get(i);
        int action = i == 0 ? MouseEvent.PRESS
            : i == path.size() - 1 ? MouseEvent.RELEASE : MouseEvent.DRAG;
        sketch.postEvent(new MouseEvent(null, p[0], action, 0, (int) p[1], (int) p[2],
            PConstants.LEFT, 1));
      }

      List<String> expected = referenceLegacyStrokes(path);
      assertTrue(expected.size() >= 4, "a square is at least four strokes: " + expected);
      waitFor(() -> library.sent().size() >= expected.size(), expected.size() + " strokes sent");
      List<String> sent = new ArrayList<>();
      for (Stroke stroke : library.sent()) {
        sent.add(Protocol.formatLegacy(stroke));
      }
      assertEquals(expected, sent, "the sketch's legacy strokes and simplify --paper's");
      waitFor(() -> library.unsent() == 0, "the broker's PUBACK of every stroke");

      waitFor(() -> heard.stream().filter(e -> SleeveEvent.PLAYED.equals(e.type())
              || SleeveEvent.ADJUSTED.equals(e.type())).count() >= expected.size(),
          expected.size() + " played events from the sleeve");
      // And the sketch got them too, inside its draw(), on its own thread.
      waitFor(() -> library.events().size() >= expected.size(), "events handed to the sketch");

      Robot robot = new Robot();
      ImageIO.write(robot.createScreenCapture(new Rectangle(0, 0, 1920, 1080)), "png",
          SCREENSHOT.toFile());
      assertTrue(Files.size(SCREENSHOT) > 0);
    } finally {
      listener.close();
    }
  }

  /** What feelmysign simplify --paper sends for the same mouse path, as legacy text. */
  private List<String> referenceLegacyStrokes(List<long[]> path) throws Exception {
    StringBuilder recording = new StringBuilder(
        "{\"canvas\": {\"width_px\": 1920, \"height_px\": 1080}, \"paths\": [[");
    for (int i = 0; i < path.size(); i++) {
      long[] p = path.get(i);
      recording.append(i == 0 ? "" : ", ").append("{\"t_ms\": ").append(p[0])
          .append(", \"x\": ").append(p[1]).append(", \"y\": ").append(p[2])
          .append(", \"pressure\": 0.5}");
    }
    recording.append("]]}");
    Path file = state.resolve("square.json");
    Files.writeString(file, recording);
    Process simplify = new ProcessBuilder(repository.resolve(".venv/bin/feelmysign").toString(),
            "simplify", file.toString(), "--paper", "--json")
        .redirectError(ProcessBuilder.Redirect.INHERIT).start();
    String out = new String(simplify.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
    assertEquals(0, simplify.waitFor(), "feelmysign simplify failed");
    @SuppressWarnings("unchecked")
    Map<String, Object> result = (Map<String, Object>) PyJson.loads(out);
    List<String> strokes = new ArrayList<>();
    for (Object item : (List<?>) result.get("strokes")) {
      Map<?, ?> s = (Map<?, ?>) item;
      List<?> start = (List<?>) s.get("start");
      List<?> end = (List<?>) s.get("end");
      strokes.add(Protocol.formatLegacy(new Stroke(num(start.get(0)), num(start.get(1)),
          num(end.get(0)), num(end.get(1)), num(s.get("duration_ms")))));
    }
    return strokes;
  }

  private static double num(Object value) {
    return ((Number) value).doubleValue();
  }

  static File screenshot() {
    return SCREENSHOT.toFile();
  }
}
