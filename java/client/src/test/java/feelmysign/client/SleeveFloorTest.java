package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertInstanceOf;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertSame;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import feelmysign.json.PyJson;
import feelmysign.simplify.Params;
import org.junit.jupiter.api.Test;

/**
 * The sleeve's floor read from its status and kept to, as the page's {@code withFloor} and
 * {@code floorNote} (web/test/sleeve-floor.test.ts) and Python's {@code respect_floor} do.
 */
class SleeveFloorTest {
  private static final SleeveFloor MOTORS = new SleeveFloor(73.701, 0.05, null);
  private static final SleeveFloor P01 = new SleeveFloor(118.4, 0.62, "P01");

  private static SleeveFloor.Read read(String json) {
    return SleeveFloor.read(PyJson.loads(json));
  }

  @Test
  void aStatusFloorIsReadWithOrWithoutItsWearer() {
    assertEquals(new SleeveFloor.Said(P01),
        read("{\"min_duration_ms\": 118.4, \"min_length\": 0.62, \"wearer\": \"P01\"}"));
    assertEquals(new SleeveFloor.Said(MOTORS),
        read("{\"min_duration_ms\": 73.701, \"min_length\": 0.05}"));
    assertEquals(new SleeveFloor.Said(new SleeveFloor(80, 0, null)),
        read("{\"min_duration_ms\": 80, \"min_length\": 0, \"wearer\": null}"));
    assertInstanceOf(SleeveFloor.Absent.class, SleeveFloor.read(null));
  }

  @Test
  void aFloorOutOfRangeOrOfTheWrongKindIsNotUnderstood() {
    String[] bad = {
      "{\"min_duration_ms\": 0, \"min_length\": 0.05}",
      "{\"min_duration_ms\": -5, \"min_length\": 0.05}",
      "{\"min_duration_ms\": 10000.5, \"min_length\": 0.05}",
      "{\"min_duration_ms\": 1e999, \"min_length\": 0.05}",
      "{\"min_duration_ms\": 73.7, \"min_length\": -0.1}",
      "{\"min_duration_ms\": 73.7, \"min_length\": 101}",
      "{\"min_duration_ms\": \"73.7\", \"min_length\": 0.05}",
      "{\"min_duration_ms\": true, \"min_length\": 0.05}",
      "{\"min_length\": 0.05}",
      "{\"min_duration_ms\": 73.7, \"min_length\": 0.05, \"wearer\": 7}",
      "[73.7, 0.05]",
    };
    for (String json : bad) {
      assertInstanceOf(SleeveFloor.NotUnderstood.class, read(json), json);
    }
    SleeveFloor.NotUnderstood said =
        (SleeveFloor.NotUnderstood) read("{\"min_duration_ms\": -5, \"min_length\": 0.05}");
    assertEquals("min_duration_ms -5 is not a duration above 0 and at most 10000 ms",
        said.problem());
    assertThrows(IllegalArgumentException.class, () -> new SleeveFloor(Double.NaN, 0, null));
  }

  @Test
  void theMotorsFloorSetsTheWindowsFloorMsAndRaisesNoMinimum() {
    Params own = Params.window().with("floor_ms", 50.0);
    Params kept = MOTORS.applyTo(own);
    assertEquals(73.701, kept.number("floor_ms"));
    assertEquals(false, kept.flag("strict_minimums"));
    assertEquals(own.number("min_duration_ms"), kept.number("min_duration_ms"));
    assertEquals(own.number("min_length"), kept.number("min_length"));
    // Already at it: the same parameters.
    assertSame(kept, MOTORS.applyTo(kept));
    // The angle simplifier has no floor_ms: unchanged.
    Params angle = Params.angle();
    assertSame(angle, MOTORS.applyTo(angle));
    assertNull(MOTORS.raisedNote(own));
  }

  @Test
  void aWearersFloorRaisesTheMinimumsNeverLowersThemAndIsStrict() {
    Params kept = P01.applyTo(Params.window());
    assertEquals(118.4, kept.number("floor_ms"));
    assertEquals(118.4, kept.number("min_duration_ms"));
    assertEquals(0.62, kept.number("min_length"));
    assertTrue(kept.flag("strict_minimums"));
    Params high = Params.window().with("min_duration_ms", 200.0).with("min_length", 0.3);
    Params raised = P01.applyTo(high);
    assertEquals(200.0, raised.number("min_duration_ms"), "a higher setting is kept");
    assertEquals(0.62, raised.number("min_length"));
    assertTrue(raised.flag("strict_minimums"));
    // The angle simplifier's minimums too (as Python's replay raises them).
    Params angle = P01.applyTo(Params.angle());
    assertEquals(118.4, angle.number("min_duration_ms"));
    assertEquals(0.62, angle.number("min_length"));
  }

  @Test
  void theNotesAreThePagesAndThePythonReferences() {
    assertEquals("At least 118.4 ms and 0.62 grid units per stroke: the sleeve's floor with wearer"
        + " P01's limits; min duration and min length raised to it.", P01.note(Params.window()));
    assertEquals("At least 118.4 ms and 0.62 grid units per stroke: the sleeve's floor with wearer"
        + " P01's limits; your settings are above it.",
        P01.note(Params.window().with("min_duration_ms", 200.0).with("min_length", 1.0)));
    assertEquals("The sleeve plays strokes briefer than 73.7 ms slowed to that, and catches up"
        + " after them; a wearer file (feelmysign sleeve --wearer) sets limits the sketch keeps"
        + " to.", MOTORS.note(Params.window()));
    assertEquals("Raised min duration 118.4 ms and min length 0.62 grid units: the sleeve's floor"
        + " with wearer P01's limits.", P01.raisedNote(Params.window()));
  }
}
