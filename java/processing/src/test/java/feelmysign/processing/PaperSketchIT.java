package feelmysign.processing;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static feelmysign.testing.LiveSleeve.waitFor;
import static org.junit.jupiter.api.Assertions.fail;

import feelmysign.json.PyJson;
import feelmysign.protocol.Protocol;
import feelmysign.protocol.Stroke;
import feelmysign.testing.LiveSleeve;
import java.awt.Rectangle;
import java.awt.Robot;
import java.io.File;
import java.io.IOException;
import java.net.URL;
import java.net.URLClassLoader;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
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
import processing.event.KeyEvent;
import processing.event.MouseEvent;

/**
 * The paper's sketch example (examples/PaperSketch) as a user runs it, on Xvfb's screen, with
 * Processing's core from Maven Central: a scripted mouse draws a square; the strokes it sends
 * are the legacy text {@code feelmysign simplify --paper} computes from the same mouse path,
 * and a real {@code feelmysign sleeve --backend sim} plays them (played events come back). The
 * two other examples too: ModernSketch sends a square drawn with the mouse as JSON v1, StudyShape
 * the library's square of 8 strokes on Enter, and the sleeve plays every stroke of each. make
 * java-test runs it under xvfb-run; a screenshot of the paper's sketch is left in target/.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class PaperSketchIT {
  private static final String SLEEVE = "sketch-test";
  static final Path SCREENSHOT = Path.of("target/paper-sketch-under-xvfb.png").toAbsolutePath();

  private Path state;
  private LiveSleeve live;
  private final List<PApplet> sketches = new ArrayList<>();

  @BeforeAll
  void startBrokerAndSleeve(@TempDir Path dir) throws Exception {
    if (System.getenv("DISPLAY") == null) {
      fail("no X display: run 'make java-test', which starts Xvfb (xvfb-run) for this test");
    }
    state = dir;
    // The sleeve with its legacy topic (deviceOne/line), as the paper's sketch sends.
    live = LiveSleeve.start(state, SLEEVE, List.of(), List.of());
  }

  @AfterAll
  void stopThem() throws InterruptedException {
    for (PApplet sketch : new ArrayList<>(sketches)) {
      retire(sketch);
    }
    if (live != null) {
      live.close();
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
    sketches.add(applet);
    PApplet.runSketch(new String[] {"--location=0,0", name}, applet);
    return applet;
  }

  /** A sketch's window closed and its client with it (exit() would end the JVM). */
  private void retire(PApplet sketch) {
    sketch.noLoop();
    sketch.getSurface().setVisible(false);
    sketch.dispose(); // the library's dispose hook closes its client
    sketches.remove(sketch);
  }

  /** An example run against the live sleeve, logged in as its sender; its library once connected. */
  private FeelMySign runConnected(String name) throws Exception {
    PApplet sketch = compileAndRun(name, Map.of(
        "BROKER", live.mqttUrl(),
        "USER", live.senderUser(),
        "PASSWORD", live.senderPassword(),
        "SLEEVE", SLEEVE));
    waitFor(() -> sketch.frameCount > 3, "frames drawn by " + name);
    java.lang.reflect.Field field = sketch.getClass().getDeclaredField("sleeve");
    field.setAccessible(true); // a sketch's fields are package-private, as the PDE makes them
    FeelMySign library = (FeelMySign) field.get(sketch);
    waitFor(library::connected, name + "'s connection to the broker");
    return library;
  }

  /** The mouse drawing {@code path} on {@code sketch}: press, drags, release. */
  private static void draw(PApplet sketch, List<long[]> path) {
    for (int i = 0; i < path.size(); i++) {
      long[] p = path.get(i);
      int action = i == 0 ? MouseEvent.PRESS
          : i == path.size() - 1 ? MouseEvent.RELEASE : MouseEvent.DRAG;
      sketch.postEvent(new MouseEvent(null, p[0], action, 0, (int) p[1], (int) p[2],
          PConstants.LEFT, 1));
    }
  }

  /** Waits until the sleeve has played (or played adjusted) every stroke {@code library} sent. */
  private static void awaitPlayed(LiveSleeve.Listening listener, FeelMySign library)
      throws InterruptedException {
    waitFor(() -> library.unsent() == 0, "the broker's PUBACK of every stroke");
    java.util.Set<String> drawings = new java.util.HashSet<>();
    library.sent().forEach(s -> drawings.add(s.drawing()));
    int count = library.sent().size();
    waitFor(() -> listener.events.stream()
            .filter(e -> drawings.contains(e.drawing()))
            .filter(e -> "played".equals(e.type()) || "adjusted".equals(e.type()))
            .count() >= count,
        count + " played events from the sleeve: " + listener.events);
    // And the sketch got them too, inside its draw(), on its own thread.
    waitFor(() -> library.events().stream().filter(e -> drawings.contains(e.drawing())).count()
        >= count, "events handed to the sketch");
  }

  @Test
  void theModernSketchSendsADrawnSquareAsJsonAndTheSleevePlaysIt() throws Exception {
    try (LiveSleeve.Listening listener = live.listen()) {
      FeelMySign library = runConnected("ModernSketch");
      PApplet sketch = sketches.get(sketches.size() - 1);
      List<long[]> path = new ArrayList<>();
      for (long[] p : squarePath()) {
        path.add(new long[] {p[0], p[1] * 3 / 5, p[2] * 3 / 5}); // onto its 1280 x 720 canvas
      }
      draw(sketch, path);
      waitFor(() -> library.sent().size() >= 4, "a square's strokes sent");
      for (Stroke stroke : library.sent()) {
        assertTrue(stroke.drawing() != null && stroke.seq() != null, "JSON v1: " + stroke);
      }
      awaitPlayed(listener, library);
      retire(sketch);
    }
  }

  @Test
  void theStudySketchSendsTheChosenShapeAndTheSleevePlaysIt() throws Exception {
    try (LiveSleeve.Listening listener = live.listen()) {
      FeelMySign library = runConnected("StudyShape");
      PApplet sketch = sketches.get(sketches.size() - 1);
      // 2: the square, at the sketch's 8 strokes; Enter sends it.
      sketch.postEvent(new KeyEvent(null, 1, KeyEvent.PRESS, 0, '2', '2'));
      sketch.postEvent(new KeyEvent(null, 2, KeyEvent.PRESS, 0, PConstants.ENTER, 10));
      List<Stroke> square =
          feelmysign.shapes.Shapes.strokes("square", 3, 4, 3.0, 10000, 8, null, 0);
      waitFor(() -> library.sent().size() >= square.size(), square.size() + " strokes sent");
      List<String> sent = new ArrayList<>();
      for (Stroke stroke : library.sent()) {
        sent.add(Protocol.formatLegacy(stroke));
      }
      List<String> expected = new ArrayList<>();
      square.forEach(stroke -> expected.add(Protocol.formatLegacy(stroke)));
      assertEquals(expected, sent, "the library's square of 8 strokes");
      awaitPlayed(listener, library);
      retire(sketch);
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
    // The sleeve's events, heard as any other sender hears them.
    try (LiveSleeve.Listening listener = live.listen()) {
      FeelMySign library = runConnected("PaperSketch");
      List<long[]> path = squarePath();
      draw(sketches.get(sketches.size() - 1), path);

      List<String> expected = referenceLegacyStrokes(path);
      assertTrue(expected.size() >= 4, "a square is at least four strokes: " + expected);
      waitFor(() -> library.sent().size() >= expected.size(), expected.size() + " strokes sent");
      List<String> sent = new ArrayList<>();
      for (Stroke stroke : library.sent()) {
        sent.add(Protocol.formatLegacy(stroke));
      }
      assertEquals(expected, sent, "the sketch's legacy strokes and simplify --paper's");
      waitFor(() -> library.unsent() == 0, "the broker's PUBACK of every stroke");

      waitFor(() -> listener.played() >= expected.size(),
          expected.size() + " played events from the sleeve");
      // And the sketch got them too, inside its draw(), on its own thread.
      waitFor(() -> library.events().size() >= expected.size(), "events handed to the sketch");

      Robot robot = new Robot();
      ImageIO.write(robot.createScreenCapture(new Rectangle(0, 0, 1920, 1080)), "png",
          SCREENSHOT.toFile());
      assertTrue(Files.size(SCREENSHOT) > 0);
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
    Process simplify = new ProcessBuilder(LiveSleeve.feelmysign().toString(),
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
