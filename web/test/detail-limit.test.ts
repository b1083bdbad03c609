/** The Detail setting says what else cuts strokes: the window simplifier's longest-stroke cap. */
import { describe, expect, it } from "vitest";
import { detailLimit } from "../src/ui/settings";

describe("detailLimit", () => {
  it("names the longest-stroke cap when it is on", () => {
    const said = detailLimit({ algorithm: "window", max_stroke_ms: 300 });
    expect(said).toContain("The longest stroke (300 ms of drawing, under Advanced) cuts too");
    expect(said).toContain("Set it to 0 for the fewest, longest strokes.");
  });

  it("says nothing when no cap limits the detail", () => {
    expect(detailLimit({ algorithm: "window", max_stroke_ms: 0 })).toBe("");
    expect(detailLimit({ algorithm: "angle", max_stroke_ms: 300 })).toBe("");
  });
});
