package feelmysign.shapes;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.fasterxml.jackson.databind.JsonNode;
import com.fasterxml.jackson.databind.ObjectMapper;
import feelmysign.Vectors;
import feelmysign.protocol.Stroke;
import feelmysign.simplify.ParameterException;
import java.nio.charset.StandardCharsets;
import java.util.List;
import org.junit.jupiter.api.Test;

/** The shapes against the reference's feelmysign.shapes, run from the repository's .venv. */
class ShapesTest {
  private static final String SCRIPT = String.join("\n",
      "import json",
      "from feelmysign.layout import Layout",
      "from feelmysign.shapes import SHAPES, shape_strokes",
      "out = []",
      "for rows, columns in ((3, 4), (4, 6)):",
      "    layout = Layout(rows=rows, columns=columns, spacing_cm=3.0)",
      "    for name, spec in SHAPES.items():",
      "        for n in range(spec.min_segments, spec.max_segments + 1, spec.step):",
      "            s = shape_strokes(name, layout=layout, segments=n, drawing='d')",
      "            out.append([rows, columns, name, n, [[t.start[0], t.start[1], t.end[0],"
          + " t.end[1], t.duration_ms] for t in s]])",
      "print(json.dumps(out))");

  @Test
  void everyShapeAtEveryResolutionIsTheReferences() throws Exception {
    Process python = new ProcessBuilder(
            Vectors.testdata().resolveSibling(".venv/bin/python").toString(), "-c", SCRIPT)
        .redirectError(ProcessBuilder.Redirect.INHERIT)
        .start();
    String text = new String(python.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
    assertEquals(0, python.waitFor(), "the reference's shapes did not run");
    JsonNode cases = new ObjectMapper().readTree(text);
    assertTrue(cases.size() > 100);
    for (JsonNode c : cases) {
      int rows = c.get(0).asInt();
      int columns = c.get(1).asInt();
      String name = c.get(2).asText();
      int n = c.get(3).asInt();
      List<Stroke> strokes = Shapes.strokes(name, rows, columns, 3.0, 10_000, n, null, 0);
      JsonNode expected = c.get(4);
      assertEquals(expected.size(), strokes.size(), name + " " + n);
      for (int i = 0; i < strokes.size(); i++) {
        Stroke s = strokes.get(i);
        double[] got = {s.startX(), s.startY(), s.endX(), s.endY(), s.durationMs()};
        for (int k = 0; k < 5; k++) {
          assertEquals(expected.get(i).get(k).asDouble(), got[k], 1e-9,
              name + " of " + n + " on " + rows + "x" + columns + ", stroke " + i);
        }
      }
    }
  }

  @Test
  void aResolutionOutOfRangeSaysTheRange() {
    ParameterException error = assertThrows(ParameterException.class,
        () -> Shapes.strokes("square", 3, 4, 3.0, 10_000, 6, null, 0));
    assertEquals("segments of a square = 6 is not allowed; it must be a multiple of 4 from 4 to 64"
        + " (each of its 4 sides split into equal strokes)", error.getMessage());
  }
}
