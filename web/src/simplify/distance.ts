/**
 * The distance of a point to a segment (squared), shared by the window simplifier's cores
 * (`window.ts`, `fit.ts`): the float operations of the Python reference, to the last bit.
 */

/** Squared distance from (px, py) to the segment (ax, ay) -> (ex, ey) (its nearest point). */
export function distanceSq(px: number, py: number, ax: number, ay: number, ex: number, ey: number): number {
  const dx = ex - ax;
  const dy = ey - ay;
  const qx = px - ax;
  const qy = py - ay;
  const lengthSq = dx * dx + dy * dy;
  return lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
}

/**
 * Squared distance from q (relative to a chord's start) to the chord d of squared length
 * `lengthSq` > 0, at its nearest point: the projection, clamped onto the chord. Its chord terms
 * computed once by the caller, for the inner loops. The clamp is written out, not with Math.max
 * and Math.min, with the same result to the last bit: t <= 0 leaves q as it is (q - 0 * d is q;
 * a zero's sign is squared away), t >= 1 subtracts d itself (1 * d is d), and a NaN t falls to
 * the projection as through Math.max and Math.min.
 */
export function chordDistanceSq(qx: number, qy: number, dx: number, dy: number, lengthSq: number): number {
  const t = (qx * dx + qy * dy) / lengthSq;
  if (t >= 1) {
    qx = qx - dx;
    qy = qy - dy;
  } else if (!(t <= 0)) {
    qx = qx - t * dx;
    qy = qy - t * dy;
  }
  return qx * qx + qy * qy;
}
