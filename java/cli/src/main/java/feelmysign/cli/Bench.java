package feelmysign.cli;

import feelmysign.json.PyJson;
import feelmysign.simplify.Algorithm;
import feelmysign.simplify.Params;
import feelmysign.simplify.Sample;
import feelmysign.simplify.Simplifier;
import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.function.LongSupplier;

/**
 * The Java simplifiers' throughput on the LASA frames the web bench reads
 * ({@code web/bench/.lasa-frames.json}, written by {@code python -m feelmysign.bench.lasa_points}),
 * each beside a baseline measured in the same JVM run: one distance per frame, the least
 * per-frame work any simplifier does. Best of several runs after a warm-up; a benchmark, not a
 * test: nothing passes or fails on timing. {@code make bench} prints it.
 */
public final class Bench {
  private Bench() {}

  private static final int RUNS = 7;

  private record Demo(double widthPx, double heightPx, List<Sample> frames) {}

  private static volatile double sink;

  public static void main(String[] args) throws IOException {
    Path file = Path.of(args.length > 0 ? args[0] : "web/bench/.lasa-frames.json");
    @SuppressWarnings("unchecked")
    Map<String, Object> document = (Map<String, Object>) PyJson.loads(Files.readString(file));
    double pressure = ((Number) document.get("pressure")).doubleValue();
    List<Demo> demos = new ArrayList<>();
    for (Object item : (List<?>) document.get("demos")) {
      Map<?, ?> demo = (Map<?, ?>) item;
      List<Sample> frames = new ArrayList<>();
      for (Object f : (List<?>) demo.get("frames")) {
        List<?> frame = (List<?>) f;
        frames.add(
            new Sample(number(frame.get(0)), number(frame.get(1)), number(frame.get(2)), pressure));
      }
      demos.add(new Demo(number(demo.get("canvas_width_px")), number(demo.get("canvas_height_px")), frames));
    }
    long total = demos.stream().mapToLong(d -> d.frames().size()).sum();
    System.out.printf(
        "Simplifiers on LASA (Java %s): %d demonstrations, %,d frames at 60 fps%n",
        System.getProperty("java.version"), demos.size(), total);
    double baseline = rate("baseline: one distance per frame", () -> baseline(demos), 0);
    rate("angle simplifier (paper's defaults)", () -> run(Algorithm.ANGLE, demos), baseline);
    rate("window simplifier (max_error 0.25)", () -> run(Algorithm.WINDOW, demos), baseline);
    rate(
        "window simplifier, least squares",
        () -> run(Algorithm.WINDOW, demos, Map.of("least_squares", true)),
        baseline);
  }

  private static double number(Object value) {
    return ((Number) value).doubleValue();
  }

  private static long baseline(List<Demo> demos) {
    double total = 0;
    long count = 0;
    for (Demo demo : demos) {
      Sample last = demo.frames().get(0);
      for (Sample f : demo.frames()) {
        double dx = f.x() - last.x();
        double dy = f.y() - last.y();
        total += Math.sqrt(dx * dx + dy * dy);
        last = f;
      }
      count += demo.frames().size();
    }
    sink = total; // keeps the loop from being optimised away
    return count;
  }

  private static long run(Algorithm algorithm, List<Demo> demos) {
    return run(algorithm, demos, Map.of());
  }

  /** The simplifier at its defaults on each demonstration's canvas, with {@code given} over them. */
  private static long run(Algorithm algorithm, List<Demo> demos, Map<String, Object> given) {
    long count = 0;
    int segments = 0;
    for (Demo demo : demos) {
      Map<String, Object> values = new HashMap<>(given);
      values.put("canvas_width_px", demo.widthPx());
      values.put("canvas_height_px", demo.heightPx());
      Params params = Params.of(algorithm, values);
      Simplifier simplifier = algorithm.make(params);
      for (Sample frame : demo.frames()) {
        segments += simplifier.push(frame).size();
      }
      segments += simplifier.end().size();
      count += demo.frames().size();
    }
    sink = segments;
    return count;
  }

  /** Frames per second, best of RUNS after one warm-up run; printed beside the baseline's. */
  private static double rate(String name, LongSupplier work, double baseline) {
    work.getAsLong(); // warm-up: class loading and the JIT
    double best = 0;
    for (int i = 0; i < RUNS; i++) {
      long start = System.nanoTime();
      long frames = work.getAsLong();
      double seconds = (System.nanoTime() - start) / 1e9;
      best = Math.max(best, frames / seconds);
    }
    String versus = baseline > 0 ? String.format("  (%.3f x the baseline)", best / baseline) : "";
    System.out.printf("  %-40s %,14.0f frames/s%s%n", name, best, versus);
    return best;
  }
}
