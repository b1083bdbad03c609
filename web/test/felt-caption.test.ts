/** The felt timeline's caption: whose times it shows, and what of the drawing was not felt. */
import { describe, expect, it } from "vitest";
import { timelineCaption } from "../src/ui/felt-panel";

describe("timelineCaption", () => {
  it("says the times are the page's own until the sleeve reports", () => {
    expect(timelineCaption(4, 0, 0)).toBe(": what would be felt, played back to back as the sleeve does.");
  });

  it("says which times are the sleeve's", () => {
    expect(timelineCaption(4, 4, 0)).toBe(", as the sleeve played them.");
    expect(timelineCaption(4, 1, 0)).toBe("; 1 as the sleeve played them, the rest as it would.");
  });

  it("never calls a stroke the duty-cycle cap kept from playing played", () => {
    expect(timelineCaption(4, 0, 1)).toBe(
      "; 1 not felt (the sleeve's duty-cycle cap kept it from playing), the rest as it would.",
    );
    expect(timelineCaption(4, 2, 2)).toBe(
      "; 2 as the sleeve played them, 2 not felt (the sleeve's duty-cycle cap kept them from playing).",
    );
  });
});

describe("timelineCaption after Stop", () => {
  it("never says the rest plays as it would once Stop was pressed", () => {
    expect(timelineCaption(6, 2, 0, { cancelled: 3, stopped: true })).toBe(
      "; 2 as the sleeve played them, 3 cancelled by Stop before they played, the rest stopped: not felt.",
    );
    expect(timelineCaption(4, 0, 0, { cancelled: 0, stopped: true })).toBe("; the rest stopped: not felt.");
    expect(timelineCaption(4, 3, 0, { cancelled: 1, stopped: true })).toBe(
      "; 3 as the sleeve played them, 1 cancelled by Stop before it played.",
    );
    expect(timelineCaption(6, 4, 0, { cancelled: 2, cut: 1, stopped: true })).toBe(
      "; 4 as the sleeve played them (1 cut short by Stop), 2 cancelled by Stop before they played.",
    );
  });
});
