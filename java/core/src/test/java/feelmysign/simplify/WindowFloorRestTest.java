package feelmysign.simplify;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.junit.jupiter.api.Test;

/**
 * A rest lends a held piece briefer than the sleeve's floor the time it needs: it then lasts the
 * floor, never a rounding below it (15000.1 + 73.701 - 15000.1 is 73.70099999999911 ms, which the
 * sleeve slows to 73.701 and reports adjusted). As Python floor_end_ms and the page's floorEndMs.
 */
class WindowFloorRestTest {
  private static final double FLOOR_MS = 73.701;

  @Test
  void aPieceLentTheFloorLastsItToTheLastBit() {
    for (double startMs : new double[] {1.2, 100.3, 2000.7, 15000.1, 612345.6}) {
      double endMs = Merger.floorEndMs(startMs, FLOOR_MS);
      assertTrue(endMs - startMs >= FLOOR_MS, "from " + startMs);
      // The least such end: the sum itself, or the double just above it where the sum falls short.
      double sum = startMs + FLOOR_MS;
      assertEquals(sum - startMs >= FLOOR_MS ? sum : Math.nextUp(sum), endMs, "from " + startMs);
    }
    assertTrue(15000.1 + FLOOR_MS - 15000.1 < FLOOR_MS); // the case the page met
  }
}
