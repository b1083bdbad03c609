import { describe, expect, it } from "vitest";
import { LEGACY_TOPIC, TELEMETRY_NAMES, strokesTopic, telemetryTopic } from "../src/mqtt/topics";

// The strings the Python sleeve subscribes and publishes to (feelmysign/topics.py).
describe("topics", () => {
  it("puts strokes and telemetry under feelmysign/<sleeve-id>/", () => {
    expect(strokesTopic("arm2")).toBe("feelmysign/arm2/strokes");
    expect(TELEMETRY_NAMES.map((name) => telemetryTopic("arm2", name))).toEqual([
      "feelmysign/arm2/status",
      "feelmysign/arm2/actuators",
      "feelmysign/arm2/events",
    ]);
  });

  it("keeps the paper's legacy topic", () => {
    expect(LEGACY_TOPIC).toBe("deviceOne/line");
  });
});
