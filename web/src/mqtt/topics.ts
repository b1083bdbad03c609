/**
 * Every MQTT topic the page uses, built in one place; a mirror of the Python
 * `feelmysign/topics.py` (same names, same strings).
 *
 *     feelmysign/<sleeve-id>/strokes     JSON v1 strokes out (QoS 1)
 *     feelmysign/<sleeve-id>/control     control messages out: cancel a drawing or everything
 *     feelmysign/<sleeve-id>/status      retained: online, layout, version
 *     feelmysign/<sleeve-id>/actuators   actuator intensities, for the preview
 *     feelmysign/<sleeve-id>/events      one message per stroke played or rejected
 *     deviceOne/line                     legacy text strokes (the paper's sleeve)
 */

export const TOPIC_ROOT = "feelmysign";
/** The paper's sleeve (appendix A.2). */
export const LEGACY_TOPIC = "deviceOne/line";
export const STROKES = "strokes";
export const CONTROL = "control";
export const TELEMETRY_NAMES = ["status", "actuators", "events"] as const;
export type TelemetryName = (typeof TELEMETRY_NAMES)[number];
/** In a subscription: every sleeve's topic of one kind. */
export const ANY_SLEEVE = "+";

export const sleeveTopic = (sleeveId: string, name: string): string => `${TOPIC_ROOT}/${sleeveId}/${name}`;

export const strokesTopic = (sleeveId: string): string => sleeveTopic(sleeveId, STROKES);

export const controlTopic = (sleeveId: string): string => sleeveTopic(sleeveId, CONTROL);

export const telemetryTopic = (sleeveId: string, name: TelemetryName): string => sleeveTopic(sleeveId, name);
