package feelmysign.simplify;

import static org.junit.jupiter.api.Assertions.assertEquals;

import com.fasterxml.jackson.databind.JsonNode;
import feelmysign.VectorFiles;
import feelmysign.Vectors;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.params.ParameterizedTest;

/**
 * Both simplifiers against every vector of testdata/angle and testdata/window: the inputs fed
 * per path and every segment (path, start, end, times, dropped reason), within the file's own
 * tolerance.
 */
class SimplifierVectorsTest {
  @ParameterizedTest(name = "{0}")
  @VectorFiles("angle")
  void angleReproducesTheReference(String name, JsonNode vector) {
    check(Algorithm.ANGLE, vector);
  }

  @ParameterizedTest(name = "{0}")
  @VectorFiles("window")
  void windowReproducesTheReference(String name, JsonNode vector) {
    check(Algorithm.WINDOW, vector);
  }

  static List<List<Sample>> paths(JsonNode vector) {
    List<List<Sample>> paths = new ArrayList<>();
    for (JsonNode path : vector.get("paths")) {
      List<Sample> samples = new ArrayList<>();
      for (JsonNode s : path) {
        samples.add(
            new Sample(
                s.get(0).doubleValue(),
                s.get(1).doubleValue(),
                s.get(2).doubleValue(),
                s.get(3).doubleValue()));
      }
      paths.add(samples);
    }
    return paths;
  }

  @SuppressWarnings("unchecked")
  static Params params(Algorithm algorithm, JsonNode vector) {
    Map<String, Object> given =
        new LinkedHashMap<>((Map<String, Object>) Vectors.plain(vector.get("params")));
    return Params.of(algorithm, given);
  }

  private static void check(Algorithm algorithm, JsonNode vector) {
    Params params = params(algorithm, vector);
    List<List<Sample>> paths = paths(vector);
    List<Integer> inputs = new ArrayList<>();
    for (List<Sample> path : paths) {
      inputs.add(algorithm.inputs(params, path).size());
    }
    List<Integer> expectedInputs = new ArrayList<>();
    vector.get("expected").get("inputs").forEach(n -> expectedInputs.add(n.asInt()));
    assertEquals(expectedInputs, inputs, "inputs per path");
    List<PathSegment> actual = Simplify.paths(params, paths);
    JsonNode expected = vector.get("expected").get("segments");
    assertEquals(expected.size(), actual.size(), "segment count");
    double tolerance = vector.get("tolerance").asDouble();
    for (int i = 0; i < actual.size(); i++) {
      JsonNode want = expected.get(i);
      PathSegment got = actual.get(i);
      Segment s = got.segment();
      String where = "segment " + i;
      assertEquals(want.get("path").asInt(), got.path(), where + " path");
      assertEquals(
          want.get("dropped").isNull() ? null : want.get("dropped").asText(),
          s.dropped(),
          where + " dropped");
      // The window simplifier's: how many pieces too short to send were merged into it.
      assertEquals(
          want.has("merged") ? want.get("merged").asInt() : 0, s.merged(), where + " merged");
      assertEquals(want.get("start").get(0).asDouble(), s.startX(), tolerance, where + " start x");
      assertEquals(want.get("start").get(1).asDouble(), s.startY(), tolerance, where + " start y");
      assertEquals(want.get("end").get(0).asDouble(), s.endX(), tolerance, where + " end x");
      assertEquals(want.get("end").get(1).asDouble(), s.endY(), tolerance, where + " end y");
      assertEquals(want.get("start_ms").asDouble(), s.startMs(), tolerance, where + " start_ms");
      assertEquals(want.get("end_ms").asDouble(), s.endMs(), tolerance, where + " end_ms");
      assertEquals(
          want.get("emitted_at_ms").asDouble(), s.emittedAtMs(), tolerance, where + " emitted");
      // The window simplifier's: how long the sleeve is to play it (as drawn unless briefer
      // than the sleeve's floor: then the floor).
      double wantDuration =
          want.has("duration_ms")
              ? want.get("duration_ms").asDouble()
              : want.get("end_ms").asDouble() - want.get("start_ms").asDouble();
      assertEquals(wantDuration, s.durationMs(), tolerance, where + " duration");
    }
    if (algorithm == Algorithm.WINDOW) {
      // The pieces merged at release into the stroke before them, path by path (nothing sent).
      WindowSimplifier simplifier = new WindowSimplifier(params);
      List<Integer> mergedBack = new ArrayList<>();
      for (List<Sample> path : paths) {
        int before = simplifier.mergedBack();
        for (Sample sample : path) {
          simplifier.push(sample);
        }
        simplifier.end();
        mergedBack.add(simplifier.mergedBack() - before);
      }
      List<Integer> expectedMergedBack = new ArrayList<>();
      vector.get("expected").get("merged_back").forEach(n -> expectedMergedBack.add(n.asInt()));
      assertEquals(expectedMergedBack, mergedBack, "merged back per path");
    }
  }
}
