/** The note Play again leaves in the log: what the sleeve does with a drawing sent all at once. */
import { describe, expect, it } from "vitest";
import { playAgainNote } from "../src/app";

describe("playAgainNote", () => {
  it("says the strokes go all at once and play back to back, in how long against the drawing", () => {
    const note = playAgainNote(52, 4_030, 13_640);
    expect(note).toBe(
      "Played again: 52 strokes sent all at once. With no pen to keep pace with, the sleeve plays them " +
        "back to back and caught up, the pauses between strokes left out; the timeline shows them so " +
        "(4.0 s, where the drawing took 13.6 s).",
    );
  });
});
