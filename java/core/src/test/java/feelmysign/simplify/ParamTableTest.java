package feelmysign.simplify;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.fasterxml.jackson.databind.JsonNode;
import feelmysign.Vectors;
import feelmysign.json.Numbers;
import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.Arguments;
import org.junit.jupiter.params.provider.MethodSource;

/**
 * The generated {@link ParamTable} against the language-neutral table it is generated from
 * (testdata/params/params.json): every row and column, and each algorithm's order. The
 * parameter tables against the reference's (testdata/angle/params.json and
 * testdata/window/params.json): every name in order, kind, default (an integer stays one),
 * range and help; and the refusals of values outside them, in the reference's words.
 */
class ParamTableTest {
  private static final JsonNode NEUTRAL =
      Vectors.read(Vectors.testdata().resolve("params/params.json"));

  private static String textOrNull(JsonNode node) {
    return node.isNull() ? null : node.asText();
  }

  private static Double numberOrNull(JsonNode node) {
    return node.isNull() ? null : node.asDouble();
  }

  private static List<String> texts(JsonNode array) {
    List<String> out = new ArrayList<>();
    array.forEach(item -> out.add(item.asText()));
    return out;
  }

  @Test
  void theGeneratedTableIsTheLanguageNeutralOne() {
    assertEquals(NEUTRAL.get("default_algorithm").asText(), ParamTable.DEFAULT_ALGORITHM);
    assertEquals(Algorithm.named(ParamTable.DEFAULT_ALGORITHM), Algorithm.DEFAULT);
    List<String> algorithms = new ArrayList<>();
    NEUTRAL.get("algorithms").fieldNames().forEachRemaining(algorithms::add);
    assertEquals(algorithms, new ArrayList<>(ParamTable.ALGORITHMS.keySet()), "algorithms");
    for (String name : algorithms) {
      List<String> order = texts(NEUTRAL.get("algorithms").get(name));
      assertEquals(order, ParamTable.ALGORITHMS.get(name), name + " order");
      assertEquals(order, new ArrayList<>(Algorithm.named(name).defaults().keySet()), name);
    }
    List<JsonNode> rows = new ArrayList<>();
    NEUTRAL.get("parameters").forEach(rows::add);
    assertEquals(
        rows.stream().map(row -> row.get("name").asText()).toList(),
        ParamTable.PARAMETERS.stream().map(ParamTable.Row::name).toList(),
        "every parameter once, in the table's order");
    Set<String> columns =
        Set.of(
            "name", "algorithms", "paper", "type", "default", "minimum", "maximum", "unit",
            "label", "help", "panel", "detail_levels", "short", "only_when");
    for (int i = 0; i < rows.size(); i++) {
      JsonNode json = rows.get(i);
      ParamTable.Row row = ParamTable.PARAMETERS.get(i);
      String name = row.name();
      Set<String> keys = new HashSet<>();
      json.fieldNames().forEachRemaining(keys::add);
      assertEquals(columns, keys, name + ": a column the Java table does not hold");
      assertEquals(texts(json.get("algorithms")), row.algorithms(), name + " algorithms");
      assertEquals(textOrNull(json.get("paper")), row.paper(), name + " paper");
      assertEquals(json.get("type").asText(), row.kind().jsonName(), name + " type");
      assertEquals(Vectors.plain(json.get("default")), row.defaultValue(), name + " default");
      assertEquals(numberOrNull(json.get("minimum")), row.minimum(), name + " minimum");
      assertEquals(numberOrNull(json.get("maximum")), row.maximum(), name + " maximum");
      assertEquals(textOrNull(json.get("unit")), row.unit(), name + " unit");
      assertEquals(json.get("label").asText(), row.label(), name + " label");
      assertEquals(json.get("help").asText(), row.help(), name + " help");
      assertEquals(textOrNull(json.get("panel")), row.panel(), name + " panel");
      List<Double> levels = null;
      if (!json.get("detail_levels").isNull()) {
        levels = new ArrayList<>();
        for (JsonNode level : json.get("detail_levels")) {
          levels.add(level.asDouble());
        }
      }
      assertEquals(levels, row.detailLevels(), name + " detail levels");
      assertEquals(textOrNull(json.get("short")), row.shortName(), name + " short");
      JsonNode condition = json.get("only_when");
      assertEquals(
          condition.isNull()
              ? null
              : new ParamTable.Condition(
                  condition.get("name").asText(), condition.get("value").asBoolean()),
          row.onlyWhen(),
          name + " only when");
      if (!condition.isNull()) {
        assertTrue(condition.get("value").isBoolean(), name + ": a condition is on a switch");
      }
    }
  }

  @Test
  void everyPaperNameOfTheTableStandsForItsParameter() {
    int aliases = 0;
    for (ParamTable.Row row : ParamTable.PARAMETERS) {
      if (row.paper() == null) {
        assertEquals(0, row.paperOffset(), row.name());
        continue;
      }
      for (String wireName : row.algorithms()) {
        Params defaults = Params.of(Algorithm.named(wireName), Map.of());
        Object ours = defaults.get(row.name());
        Object papers = defaults.get(row.paper());
        if (row.kind() == ParamSpec.Kind.BOOLEAN) {
          assertEquals(ours, papers, row.paper());
        } else {
          assertEquals(ours.getClass(), papers.getClass(), row.paper() + " keeps the kind");
          assertEquals(
              ParamSpec.toDouble(ours) - row.paperOffset(),
              ParamSpec.toDouble(papers),
              row.paper());
        }
        assertEquals(defaults, defaults.with(row.paper(), papers), row.paper() + " round trip");
      }
      aliases += row.paper().equals(row.name()) ? 0 : 1;
    }
    assertTrue(aliases >= 10, "appendix B.1 names most parameters: " + aliases);
  }

  static Stream<Arguments> tables() {
    return Stream.of(
        Arguments.of(Algorithm.ANGLE, "angle/params.json"),
        Arguments.of(Algorithm.WINDOW, "window/params.json"));
  }

  private static List<JsonNode> parameters(String file) {
    List<JsonNode> out = new ArrayList<>();
    Vectors.read(Vectors.testdata().resolve(file)).get("parameters").forEach(out::add);
    return out;
  }

  @ParameterizedTest(name = "{1}")
  @MethodSource("tables")
  void tableIsTheReferences(Algorithm algorithm, String file) {
    List<JsonNode> table = parameters(file);
    assertEquals(
        table.stream().map(p -> p.get("name").asText()).toList(),
        new ArrayList<>(algorithm.defaults().keySet()),
        "names in the reference's order");
    for (JsonNode row : table) {
      String name = row.get("name").asText();
      ParamSpec spec = algorithm.specs().get(name);
      assertEquals(row.get("type").asText(), spec.kind().jsonName(), name + " type");
      assertEquals(row.get("help").asText(), spec.help(), name + " help");
      assertEquals(
          row.get("minimum").isNull() ? null : row.get("minimum").asDouble(),
          spec.minimum(),
          name + " minimum");
      assertEquals(
          row.get("maximum").isNull() ? null : row.get("maximum").asDouble(),
          spec.maximum(),
          name + " maximum");
      assertEquals(Vectors.plain(row.get("default")), algorithm.defaults().get(name), name);
    }
  }

  @ParameterizedTest(name = "{1}")
  @MethodSource("tables")
  void outOfRangeNamesParameterValueAndRange(Algorithm algorithm, String file) {
    for (JsonNode row : parameters(file)) {
      String name = row.get("name").asText();
      if (row.get("type").asText().equals("boolean")) {
        ParameterException error =
            assertThrows(ParameterException.class, () -> Params.of(algorithm, Map.of(name, 1L)));
        assertEquals(name + " = 1 is not allowed; it must be true or false", error.getMessage());
        continue;
      }
      double above = row.get("maximum").asDouble() + 1;
      String range =
          "["
              + Numbers.pythonG(row.get("minimum").asDouble())
              + ", "
              + Numbers.pythonG(row.get("maximum").asDouble())
              + "]";
      ParameterException error =
          assertThrows(ParameterException.class, () -> Params.of(algorithm, Map.of(name, above)));
      assertEquals(name, error.name());
      assertEquals(
          name + " = " + Numbers.pythonRepr(above) + " is not allowed; it must be in " + range,
          error.getMessage());
      ParameterException text =
          assertThrows(ParameterException.class, () -> Params.of(algorithm, Map.of(name, "x")));
      assertEquals(
          name + " = 'x' is not allowed; it must be a number in " + range, text.getMessage());
      if (row.get("type").asText().equals("integer")) {
        ParameterException half =
            assertThrows(
                ParameterException.class,
                () -> Params.of(algorithm, Map.of(name, row.get("minimum").asDouble() + 0.5)));
        assertTrue(half.getMessage().endsWith("it must be a whole number in " + range));
      }
    }
  }

  @Test
  void thePapersNamesWorkAsAppendixB1() {
    Params paper =
        Params.angle()
            .with("frameMax", 60)
            .with("checkFrame", 7)
            .with("maxAngleDifDeg", 30)
            .with("fps", 30)
            .with("clickClear", false)
            .with("recover", false)
            .with("sleeveX", 5)
            .with("sleeveY", 3)
            .with("screenX", 800)
            .with("screenY", 600)
            .with("minimumDuration", 10.5)
            .with("minimumSize", 0.2);
    assertEquals(60L, paper.get("frame_max"));
    assertEquals(7L, paper.get("check_frames"));
    assertEquals(30L, paper.get("max_angle_deg"));
    assertEquals(30L, paper.get("fps"));
    assertEquals(false, paper.get("clear_on_press"));
    assertEquals(false, paper.get("recover"));
    assertEquals(6, paper.columns(), "sleeveX counts from 0");
    assertEquals(4, paper.rows(), "sleeveY counts from 0");
    assertEquals(5L, paper.get("sleeveX"));
    assertEquals(800L, paper.get("canvas_width_px"));
    assertEquals(600L, paper.get("canvas_height_px"));
    assertEquals(10.5, paper.get("min_duration_ms"));
    assertEquals(0.2, paper.get("min_length"));
    ParameterException error =
        assertThrows(ParameterException.class, () -> Params.angle().with("sleeveX", 64));
    assertEquals(
        "sleeveX = 64 is not allowed; it must be a whole number in [0, 63]".replace(
            "a whole number in", "in"),
        error.getMessage());
    IllegalArgumentException other =
        assertThrows(IllegalArgumentException.class, () -> Params.angle().with("max_error", 1));
    assertTrue(other.getMessage().contains("only applies to the window simplifier"));
  }

  @Test
  void aFloatIsTakenAsTheDecimalItPrintsAs() {
    // Processing's literals are floats: 0.1f is meant as 0.1, not its exact 0.10000000149011612.
    assertEquals(0.10000000149011612, (double) 0.1f);
    Params window = Params.window().with("max_error", 0.1f).with("rest_ms", 150.5f);
    assertEquals(0.1, window.get("max_error"));
    assertEquals(150.5, window.get("rest_ms"));
    assertEquals("0.1", String.valueOf(window.values().get("max_error")));
    // The same parameters as from a double, so the same strokes.
    assertEquals(Params.window().with("max_error", 0.1).with("rest_ms", 150.5), window);
    assertEquals(1.0E-3, Params.window().with("max_error", 1e-3f).get("max_error"));
    assertEquals(1800.0, Params.angle().with("screenX", 1800f).get("canvas_width_px"));
    // Still checked against the range, and said as it was written (in Python's repr).
    ParameterException out =
        assertThrows(ParameterException.class, () -> Params.window().with("max_error", 0.0001f));
    assertEquals("max_error = 0.0001 is not allowed; it must be in [0.001, 100]", out.getMessage());
  }

  @Test
  void theParametersOfTheOtherAlgorithmAreRefused() {
    IllegalArgumentException paper =
        assertThrows(IllegalArgumentException.class, () -> Params.window().with("checkFrame", 5));
    assertEquals("checkFrame only applies to the angle simplifier", paper.getMessage());
    IllegalArgumentException read =
        assertThrows(IllegalArgumentException.class, () -> Params.window().get("checkFrame"));
    assertEquals("checkFrame only applies to the angle simplifier", read.getMessage());
    IllegalArgumentException unknown =
        assertThrows(IllegalArgumentException.class, () -> Params.window().with("colour", 5));
    assertTrue(unknown.getMessage().startsWith("the window simplifier has no parameter colour;"));
    assertTrue(unknown.getMessage().contains("sleeveX"), unknown.getMessage());
    assertFalse(unknown.getMessage().contains("checkFrame"), "the angle's paper names");
  }
}
