/** The drawing area: the sleeve's aspect, turned a quarter only where that uses the screen much better. */
import { describe, expect, it } from "vitest";
import { AREA_MARGIN_PX, chooseArea, fitArea, TURN_GAIN } from "../src/ui/geometry";

const SLEEVE = { rows: 3, columns: 4 };

describe("chooseArea", () => {
  it("turns a landscape sleeve on an upright phone, and gains about twice the area", () => {
    const { area, turned } = chooseArea(SLEEVE, 366, 560);
    expect(turned).toBe(true);
    // In the sleeve's orientation still: 3:2, its width laid down the screen.
    expect(area.width_px / area.height_px).toBeCloseTo(1.5, 1);
    expect(area.height_px).toBeLessThanOrEqual(366 - 2 * AREA_MARGIN_PX);
    expect(area.width_px).toBeLessThanOrEqual(560 - 2 * AREA_MARGIN_PX);
    const upright = fitArea(SLEEVE, 366, 560);
    expect(area.width_px * area.height_px).toBeGreaterThan(2 * upright.width_px * upright.height_px);
  });

  it("keeps the sleeve upright on a landscape screen and on a near-square one", () => {
    expect(chooseArea(SLEEVE, 1200, 700).turned).toBe(false);
    expect(chooseArea(SLEEVE, 800, 380).turned).toBe(false);
    // Turned would be larger here, but not by TURN_GAIN: no flip at every small resize.
    const square = chooseArea(SLEEVE, 500, 520);
    expect(square.turned).toBe(false);
    expect(square.area).toEqual(fitArea(SLEEVE, 500, 520));
  });

  it("turns exactly when the turned area is more than TURN_GAIN times the upright one", () => {
    for (let height = 300; height <= 900; height += 7) {
      const upright = fitArea(SLEEVE, 400, height);
      const across = fitArea({ rows: SLEEVE.columns, columns: SLEEVE.rows }, 400, height);
      const gain = (across.width_px * across.height_px) / (upright.width_px * upright.height_px);
      expect(chooseArea(SLEEVE, 400, height).turned, `height ${height}`).toBe(gain > TURN_GAIN);
    }
  });

  it("never turns a square sleeve", () => {
    expect(chooseArea({ rows: 4, columns: 4 }, 390, 844).turned).toBe(false);
  });
});
