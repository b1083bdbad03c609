/**
 * The angle simplifier: the online algorithm of "Can You Feel My Sign?"
 * (section 4.4, appendix B.4), ported from the Python reference
 * `feelmysign/simplify/angle.py`, which it reproduces exactly on the shared
 * vectors in `testdata/angle/`.
 *
 * Every `check_frames` frames it compares the direction of the line drawn so
 * far (start -> pointer) with the direction of the latest movement (pointer at
 * the last check -> pointer). When they differ by more than `max_angle_deg`
 * the line up to the last check is finished and a new one begins there. Pure
 * and streaming: `push` one animation frame at a time (canvas pixels, with its
 * real time), `end` on release; both return the segments finished by that call.
 * The readings chosen where the paper's pseudo-code is ambiguous are listed in
 * docs/research.md; the float operations follow the reference's order.
 */
import { CanvasMapping } from "./mapping";
import { checkAngleParams, type AngleParams } from "./params";
import { finishSegment, type Sample, type Segment } from "./segment";

/** Movements shorter than this (pixels) have no direction. */
const STILL_PX = 1e-9;

/** The line being drawn: where it starts and where its last passed check was. */
interface Line {
  start: Sample;
  last: Sample;
  framesSinceCheck: number;
  framesInLine: number;
}

export class AngleSimplifier {
  readonly params: AngleParams;
  readonly #cosMax: number;
  readonly #mapping: CanvasMapping;
  #line: Line | null = null;
  #pointer: Sample | null = null;

  constructor(params: AngleParams) {
    checkAngleParams(params);
    this.params = params;
    // Python's math.radians multiplies by pi/180 computed first.
    this.#cosMax = Math.cos(params.max_angle_deg * (Math.PI / 180));
    this.#mapping = CanvasMapping.fromParams(params);
  }

  /** True between the first frame of a path and `end`. */
  get drawing(): boolean {
    return this.#line !== null;
  }

  /** Where the line being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    return this.#line?.start ?? null;
  }

  /** One animation frame while the pointer is down; the first frame of a path is the press. */
  push(frame: Sample): Segment[] {
    this.#pointer = frame;
    const line = this.#line;
    if (line === null) {
      this.#line = newLine(frame);
      return [];
    }
    const out: Segment[] = [];
    line.framesSinceCheck += 1;
    line.framesInLine += 1;
    if (line.framesSinceCheck >= this.params.check_frames) this.#check(line, frame, out);
    if (this.params.frame_max && line.framesInLine > this.params.frame_max) {
      out.push(this.#finish(line.start, frame));
      this.#line = newLine(frame);
    }
    return out;
  }

  /** Release: the rest of the path as one line, or two if it turned since the last check. */
  end(): Segment[] {
    const line = this.#line;
    const pointer = this.#pointer;
    this.#line = null;
    if (line === null || pointer === null) return [];
    // Identity, as in the reference: `last` is `start` until a check has passed.
    if (line.last !== line.start && this.#turned(line, pointer)) {
      return [this.#finish(line.start, line.last), this.#finish(line.last, pointer)];
    }
    return [this.#finish(line.start, pointer)];
  }

  #check(line: Line, frame: Sample, out: Segment[]): void {
    if (this.#turned(line, frame)) {
      out.push(this.#finish(line.start, line.last));
      if (this.params.recover) {
        line.start = line.last;
        line.framesInLine = line.framesSinceCheck;
      } else {
        line.start = frame;
        line.framesInLine = 0;
      }
    }
    line.last = frame;
    line.framesSinceCheck = 0;
  }

  /** Whether start -> frame and last check -> frame differ by more than the maximum angle. */
  #turned(line: Line, frame: Sample): boolean {
    const ux = frame.x - line.start.x;
    const uy = frame.y - line.start.y;
    const vx = frame.x - line.last.x;
    const vy = frame.y - line.last.y;
    const moved = Math.sqrt(vx * vx + vy * vy);
    // The pointer rested since the last check: no new direction.
    if (moved <= STILL_PX) return false;
    const lineSoFar = Math.sqrt(ux * ux + uy * uy);
    // It moved, back onto the line's start: a full reversal.
    if (lineSoFar <= STILL_PX) return true;
    return (ux * vx + uy * vy) / (lineSoFar * moved) < this.#cosMax;
  }

  #finish(start: Sample, end: Sample): Segment {
    return finishSegment(
      this.#mapping.toGrid(start.x, start.y),
      this.#mapping.toGrid(end.x, end.y),
      start.t_ms,
      end.t_ms,
      this.#pointer ? this.#pointer.t_ms : end.t_ms,
      this.params,
    );
  }
}

function newLine(frame: Sample): Line {
  return { start: frame, last: frame, framesSinceCheck: 0, framesInLine: 0 };
}
