/** Actuator telemetry parsing: the sleeve's frames, and anything else a broker may deliver. */
import { describe, expect, it } from "vitest";
import { parseActuators } from "../src/telemetry";

describe("telemetry", () => {
  it("reads actuator frames and clamps intensities into 0..1", () => {
    const frame = parseActuators('{"t_ms":5,"rows":1,"columns":3,"intensities":[[0,1.5,-1]]}');
    expect(frame).toEqual({ t_ms: 5, rows: 1, columns: 3, intensities: [[0, 1, 0]] });
  });

  it.each([
    '{"rows":2,"columns":2,"intensities":[[0,0]]}',
    '{"rows":1,"columns":2,"intensities":[[0]]}',
    '{"rows":1,"columns":1,"intensities":[["a"]]}',
  ])("refuses a malformed actuator frame %s", (text) => {
    expect(parseActuators(text)).toBeNull();
  });
});
