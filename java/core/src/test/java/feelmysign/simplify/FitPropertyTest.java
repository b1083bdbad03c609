package feelmysign.simplify;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Random;
import org.junit.jupiter.api.Test;

/**
 * The window simplifier with its least-squares core ({@code least_squares}, {@link FitCore}) on
 * random pointer paths (a seeded generator) with random valid parameters: every drawn sample lies
 * within max_error of a sent stroke, a path's strokes join end to start, and a stroke drawn
 * briefer than the sleeve's floor is sent lasting the floor (one drawn longer, as drawn).
 */
class FitPropertyTest {
  /** Room for a distance computed another way than the simplifier's (last bits only). */
  private static final double FLOAT_TOLERANCE = 1e-12;

  private static final double[] MAX_ERRORS = {0.02, 0.05, 0.1, 0.15, 0.25, 1.0};
  private static final int[] MAX_WINDOWS = {1, 3, 8, 256};
  private static final double[] MAX_STROKE_MS = {0.0, 50.0, 100.0, 200.0};
  private static final double[] LOOKAHEADS_MS = {0.0, 30.0, 100.0};
  private static final double[] FLOORS_MS = {0.0, 20.0, 73.701, 150.0};
  private static final double[] RESTS_MS = {0.0, 30.0, 100.0};
  private static final double[] MIN_DURATIONS_MS = {0.0, 6.1, 80.0};
  private static final double[] MIN_LENGTHS = {0.0, 0.1, 0.4};

  private static double pick(Random random, double[] values) {
    return values[random.nextInt(values.length)];
  }

  private static Params params(Random random) {
    return Params.window()
        .with("least_squares", true)
        .with("max_error", pick(random, MAX_ERRORS))
        .with("max_window", MAX_WINDOWS[random.nextInt(MAX_WINDOWS.length)])
        .with("max_stroke_ms", pick(random, MAX_STROKE_MS))
        .with("lookahead_ms", pick(random, LOOKAHEADS_MS))
        .with("floor_ms", pick(random, FLOORS_MS))
        .with("rest_ms", pick(random, RESTS_MS))
        .with("min_duration_ms", pick(random, MIN_DURATIONS_MS))
        .with("min_length", pick(random, MIN_LENGTHS))
        .with("stretch", random.nextBoolean())
        .with("canvas_width_px", 800.0)
        .with("canvas_height_px", 600.0);
  }

  /**
   * A pointer path of 1 to 200 samples within 50 px of the 800 x 600 canvas: steps of up to 40
   * px, now and then a still pen (a rest, if long enough) or a jitter, times 0 to 30 ms apart,
   * now and then equal or a step back (times never run backwards: the simplifier takes the
   * earlier sample's).
   */
  private static List<Sample> path(Random random) {
    int count = 1 + random.nextInt(200);
    List<Sample> samples = new ArrayList<>(count);
    double x = random.nextDouble() * 900 - 50;
    double y = random.nextDouble() * 700 - 50;
    double t = random.nextDouble() * 1000;
    for (int i = 0; i < count; i++) {
      samples.add(new Sample(t, x, y));
      double move = random.nextDouble();
      if (move < 0.1) {
        // The pen stays.
      } else if (move < 0.15) {
        x += random.nextDouble() - 0.5;
        y += random.nextDouble() - 0.5;
      } else {
        x = Math.min(Math.max(x + random.nextDouble() * 80 - 40, -50), 850);
        y = Math.min(Math.max(y + random.nextDouble() * 80 - 40, -50), 650);
      }
      double step = random.nextDouble();
      t += step < 0.05 ? 0.0 : step < 0.08 ? -random.nextDouble() * 5 : random.nextDouble() * 30;
    }
    return samples;
  }

  @Test
  void strokesKeepTheBoundJoinAndLastTheFloor() {
    Random random = new Random(23);
    int strokesSeen = 0;
    int briefSeen = 0;
    for (int run = 0; run < 400; run++) {
      Params params = params(random);
      WindowSimplifier simplifier = new WindowSimplifier(params);
      CanvasMapping mapping = params.mapping();
      double maxError = params.number("max_error");
      double floorMs = Math.max(params.number("floor_ms"), params.number("min_duration_ms"));
      int paths = 1 + random.nextInt(3);
      for (int p = 0; p < paths; p++) {
        List<Sample> samples = path(random);
        List<Segment> strokes = new ArrayList<>();
        for (Sample sample : samples) {
          strokes.addAll(simplifier.push(sample));
        }
        strokes.addAll(simplifier.end());
        String where = "run " + run + " path " + p + " " + params;
        assertTrue(!strokes.isEmpty(), where + ": a path sends at least one stroke");
        strokesSeen += strokes.size();
        if (strokes.size() > 1) {
          for (Segment s : strokes) {
            assertTrue(s.sent(), where + ": only a path's lone piece may be dropped: " + s);
          }
        }
        for (Sample sample : samples) {
          double x = mapping.gridX(sample.x());
          double y = mapping.gridY(sample.y());
          double nearest = Double.POSITIVE_INFINITY;
          for (Segment s : strokes) {
            if (s.sent()) {
              double d =
                  WindowCore.distanceSq(x, y, s.startX(), s.startY(), s.endX(), s.endY());
              nearest = Math.min(nearest, Math.sqrt(d));
            }
          }
          if (strokes.get(0).sent()) {
            assertTrue(
                nearest <= maxError + FLOAT_TOLERANCE,
                where + ": sample " + sample + " lies " + nearest + " from every stroke");
          }
        }
        for (int i = 1; i < strokes.size(); i++) {
          Segment before = strokes.get(i - 1);
          Segment after = strokes.get(i);
          assertEquals(before.endX(), after.startX(), 0.0, where + ": stroke " + i + " joins (x)");
          assertEquals(before.endY(), after.startY(), 0.0, where + ": stroke " + i + " joins (y)");
          assertTrue(
              before.endMs() <= after.startMs(),
              where + ": stroke " + i + " starts after the one before ends");
        }
        for (Segment s : strokes) {
          if (!s.sent()) {
            continue;
          }
          if (s.drawnMs() < floorMs) {
            briefSeen++;
            assertEquals(
                floorMs, s.durationMs(), 0.0, where + ": a brief stroke lasts the floor: " + s);
          } else {
            assertEquals(
                s.drawnMs(), s.durationMs(), 0.0, where + ": a stroke lasts as drawn: " + s);
          }
        }
      }
    }
    // The cases reach what they test: many strokes, some of them briefer than the floor.
    assertTrue(strokesSeen > 2000, "strokes: " + strokesSeen);
    assertTrue(briefSeen > 50, "brief strokes: " + briefSeen);
  }
}
