package feelmysign.simplify;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Random;
import org.junit.jupiter.api.Test;

/**
 * The window simplifier drops no piece: on random pointer paths (a seeded generator) with
 * random valid parameters, every drawn sample lies within max_error of a sent stroke, or the
 * path is one piece too short in all (a tap), dropped with its reason.
 */
class WindowMergeTest {
  /** Room for a distance computed another way than the simplifier's (last bits only). */
  private static final double FLOAT_TOLERANCE = 1e-12;

  private static final double[] MAX_ERRORS = {0.001, 0.05, 0.1, 0.15, 0.25, 1.0};
  private static final int[] MAX_WINDOWS = {1, 2, 5, 64, 1000};
  private static final double[] MAX_STROKE_MS = {0.0, 50.0, 200.0, 300.0};
  private static final double[] MIN_LENGTHS = {0.0, 0.1, 0.4};
  private static final double[] MIN_DURATIONS_MS = {0.0, 6.1, 80.0};
  private static final double[] MAX_BENDS = {0.0, 0.1, 0.3};
  private static final double[] BEND_FLOORS = {0.0, 0.05, 0.1};
  private static final double[] FLOORS_MS = {0.0, 73.7, 200.0};

  private static double pick(Random random, double[] values) {
    return values[random.nextInt(values.length)];
  }

  private static Params params(Random random) {
    return Params.window()
        .with("max_error", pick(random, MAX_ERRORS))
        .with("max_window", MAX_WINDOWS[random.nextInt(MAX_WINDOWS.length)])
        .with("max_stroke_ms", pick(random, MAX_STROKE_MS))
        .with("min_length", pick(random, MIN_LENGTHS))
        .with("min_duration_ms", pick(random, MIN_DURATIONS_MS))
        .with("max_bend", pick(random, MAX_BENDS))
        .with("bend_floor", pick(random, BEND_FLOORS))
        .with("floor_ms", pick(random, FLOORS_MS))
        .with("stretch", random.nextBoolean())
        .with("canvas_width_px", 800.0)
        .with("canvas_height_px", 600.0);
  }

  /** A pointer path of 1 to 151 samples, kept within 50 px of the 800 x 600 canvas. */
  private static List<Sample> path(Random random) {
    int count = 1 + random.nextInt(151);
    List<Sample> samples = new ArrayList<>(count);
    double x = random.nextDouble() * 900 - 50;
    double y = random.nextDouble() * 700 - 50;
    double t = 0.0;
    samples.add(new Sample(t, x, y));
    for (int i = 1; i < count; i++) {
      x = Math.min(Math.max(x + random.nextDouble() * 80 - 40, -50), 850);
      y = Math.min(Math.max(y + random.nextDouble() * 80 - 40, -50), 650);
      t += random.nextDouble() * 30;
      samples.add(new Sample(t, x, y));
    }
    return samples;
  }

  @Test
  void everyDrawnSampleLiesWithinMaxErrorOfASentStroke() {
    Random random = new Random(19);
    for (int run = 0; run < 2000; run++) {
      Params params = params(random);
      List<Sample> samples = path(random);
      WindowSimplifier simplifier = new WindowSimplifier(params);
      List<Segment> segments = new ArrayList<>();
      for (Sample sample : samples) {
        segments.addAll(simplifier.push(sample));
      }
      segments.addAll(simplifier.end());
      String where = "run " + run + " " + params;
      if (segments.stream().anyMatch(s -> !s.sent())) {
        assertEquals(1, segments.size(), where + ": only a lone piece is dropped");
        Segment tap = segments.get(0);
        assertNotNull(tap.dropped(), where);
        assertTrue(
            tap.length() < params.number("min_length")
                || tap.durationMs() < params.number("min_duration_ms"),
            where + ": a dropped piece is too short or too brief");
        continue;
      }
      CanvasMapping mapping = params.mapping();
      double maxError = params.number("max_error");
      for (Sample sample : samples) {
        double x = mapping.gridX(sample.x());
        double y = mapping.gridY(sample.y());
        double nearest = Double.POSITIVE_INFINITY;
        for (Segment s : segments) {
          double d =
              Math.sqrt(WindowCore.distanceSq(x, y, s.startX(), s.startY(), s.endX(), s.endY()));
          nearest = Math.min(nearest, d);
        }
        assertTrue(
            nearest <= maxError + FLOAT_TOLERANCE,
            where + ": sample " + sample + " lies " + nearest + " from every stroke");
      }
    }
  }
}
