/**
 * An intensity as every page says it: the drive level, intensity × 100 %, the scale of the
 * stroke's `intensity`, the layout's `max_intensity`, the wearer's ceiling, `feelmysign send`
 * and the sleeve's status. Never a share of the layout's maximum: a ceiling of 0.6 is "60 %" on
 * the wearer's page and on the sender's.
 */
export function drivePercent(intensity: number): string {
  return `${Math.round(intensity * 100)} %`;
}
