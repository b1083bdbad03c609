/** Telemetry parsing: the sleeve's messages, and anything else a broker may deliver. */
import { describe, expect, it } from "vitest";
import { parseActuators, parseEvent, parseStatus } from "../src/telemetry";

describe("telemetry", () => {
  it("reads a status with its layout", () => {
    const status = parseStatus(
      '{"online":true,"layout":{"rows":4,"columns":6,"spacing_cm":2.5},"version":"0.1"}',
    );
    expect(status).toEqual({
      online: true,
      layout: { rows: 4, columns: 6, spacing_cm: 2.5 },
      version: "0.1",
    });
  });

  it("reads the last will (offline, no layout)", () => {
    expect(parseStatus('{"online":false}')).toEqual({ online: false, layout: null, version: null });
  });

  it.each(["", "null", "[]", '{"online":"yes"}', "{", '"online"'])("refuses status %j", (text) => {
    expect(parseStatus(text)).toBeNull();
  });

  it("ignores a layout outside 1..64", () => {
    expect(parseStatus('{"online":true,"layout":{"rows":0,"columns":4}}')?.layout).toBeNull();
  });

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

  it("reads events and keeps only known types", () => {
    expect(
      parseEvent('{"type":"rejected","reason":"outside_grid","seq":3,"drawing":"d","message":"m"}'),
    ).toEqual({
      type: "rejected",
      reason: "outside_grid",
      message: "m",
      drawing: "d",
      seq: 3,
      duration_ms: null,
      requested_duration_ms: null,
      row: null,
      column: null,
    });
    expect(parseEvent('{"type":"exploded"}')).toBeNull();
    expect(
      parseEvent(
        '{"type":"adjusted","seq":1,"reason":"too_fast","duration_ms":620,"requested_duration_ms":120}',
      ),
    ).toMatchObject({ type: "adjusted", duration_ms: 620, requested_duration_ms: 120 });
    expect(parseEvent('{"type":"safety","reason":"max_on_time","row":1,"column":2}')).toMatchObject({
      type: "safety",
      row: 1,
      column: 2,
    });
    expect(parseEvent('{"type":"played","seq":-1}')?.seq).toBeNull();
  });
});
