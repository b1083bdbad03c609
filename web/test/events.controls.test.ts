/** The wearer's controls read from the sleeve's status (events.ts, `SleeveStatus.controls`). */
import { describe, expect, it } from "vitest";
import { parseStatus, readStatus } from "../src/events";

/** The status as docs/protocol.md and the sleeve's contract write it. */
const PAUSED_STATUS = {
  online: true,
  sleeve_id: "sleeve",
  controls: { paused: true, paused_by: "button", ceiling: 0.6, do_not_disturb_until_ms: 1795330000000 },
};

describe("the status's controls", () => {
  it("reads the four fields of the contract", () => {
    expect(readStatus(PAUSED_STATUS)?.controls).toEqual({
      paused: true,
      paused_by: "button",
      ceiling: 0.6,
      do_not_disturb_until_ms: 1795330000000,
    });
  });

  it("takes a status without controls (an older sleeve, a last will) as having none", () => {
    expect(readStatus({ online: true, sleeve_id: "s" })?.controls).toBeUndefined();
    expect(readStatus({ online: false })?.controls).toBeUndefined();
    expect(readStatus({ online: true, controls: null })?.controls).toBeUndefined();
  });

  it.each([
    ["paused as a string", { paused: "true", paused_by: null, ceiling: null, do_not_disturb_until_ms: null }],
    ["paused missing", { paused_by: null, ceiling: null, do_not_disturb_until_ms: null }],
    ["paused_by a number", { paused: true, paused_by: 3, ceiling: null, do_not_disturb_until_ms: null }],
    ["ceiling above 1", { paused: false, paused_by: null, ceiling: 1.5, do_not_disturb_until_ms: null }],
    ["ceiling negative", { paused: false, paused_by: null, ceiling: -0.1, do_not_disturb_until_ms: null }],
    ["ceiling a string", { paused: false, paused_by: null, ceiling: "0.6", do_not_disturb_until_ms: null }],
    ["until a fraction", { paused: false, paused_by: null, ceiling: null, do_not_disturb_until_ms: 1.5 }],
    ["until a string", { paused: false, paused_by: null, ceiling: null, do_not_disturb_until_ms: "14:30" }],
    ["controls a list", [true]],
    ["controls a flag", true],
  ])("refuses a status whose controls have %s", (_name, controls) => {
    expect(readStatus({ online: true, controls })).toBeNull();
  });

  it("parses the text of a status message, and gives null for text that is not JSON", () => {
    expect(parseStatus(JSON.stringify(PAUSED_STATUS))?.controls?.paused).toBe(true);
    expect(parseStatus("{not json")).toBeNull();
  });
});
