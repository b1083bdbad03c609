/**
 * The window simplifier: an error-bounded online simplifier over every drawn
 * sample, cut at features, ported from the Python reference
 * `feelmysign/simplify/window.py`, which it reproduces exactly on the shared
 * vectors in `testdata/window/` (the method and its sources are described there
 * and in docs/research.md).
 *
 * It takes every pointer sample (every pointer event, coalesced ones included),
 * not animation frames. A stroke grows one sample at a time from its anchor;
 * when a sample would put a sample since the anchor farther than `max_error`
 * (grid units) from the stroke, the stroke is cut at the sample farthest from
 * the chord (among those whose own stroke keeps the bound), emitted now, and
 * the samples after the cut are taken again into the next stroke; a cut that
 * would end a piece briefer than the sleeve's floor is made at the farthest of
 * the samples drawn at least the floor after the anchor, where the window holds
 * one. A stroke
 * long enough to send lasts at most `max_stroke_ms` of drawing (the latency cap) and holds at most
 * `max_window` samples (the work cap). The stroke after one the latency cap
 * ended, if the cap or the release ends it too, ends on the line of the stroke
 * before (its end sample projected onto it) when the bound allows and that end
 * stays on the grid, so a straight line cut by the cap stays straight. A stroke still too
 * short to send after `max_stroke_ms` (a crawling pen) starts later rather than lasting longer.
 * A pen resting `rest_ms` ends the stroke before the rest, and the rest is not played. Too short
 * or too brief pieces merge into the next (`Merger`); a path's last piece briefer than the floor
 * merges at release into the stroke already sent before it where every drawn sample it has not
 * covered lies within max_error of that stroke (nothing more is sent: `mergedBack` counts them);
 * only a tap is dropped with its reason (with `strict_minimums`, also a path's last piece below
 * the minimums that the stroke before cannot cover). With `least_squares` on, the pieces are the
 * least-squares core's instead (`FitCore`, `fit.ts`), which the merger sends as they are, a brief
 * one to last the floor, unless strict minimums hold them (`Merger`'s `holdShort`). The float
 * operations follow the reference's order.
 */
import { chordDistanceSq, distanceSq } from "./distance";
import { FitCore } from "./fit";
import { CanvasMapping } from "./mapping";
import {
  finishSegment,
  NOT_ENOUGH_DISTANCE,
  NOT_ENOUGH_DURATION,
  segmentLength,
  type DropReason,
  type Point,
  type Sample,
  type Segment,
} from "./segment";
import { restRadius } from "./rest";
import { checkWindowParams, type WindowParams } from "./window-params";

export { REST_SHARE, REST_SPEED_PX_PER_MS, restRadius } from "./rest";

/**
 * The latency cap cuts at a feature drawn at least this share of max_stroke_ms after the
 * stroke's start, so that the stroke it ends is not too brief to be felt in its drawn time.
 */
const CAP_FEATURE_SHARE = 0.5;
/**
 * A stroke whose samples all lie within this share of max_error of its chord is straight
 * (rounding, not a feature): the cap cuts it at its last sample, as late as it can.
 */
const STRAIGHT = 1e-6;
/**
 * A stroke the latency cap ends is a line when all its samples lie within this share of
 * max_error of it; the stroke after it then goes on along that line where the bound allows, by
 * moving its end at most this share of max_error off its drawn sample (no drift along a bend).
 */
export const LINE_SHARE = 0.25;

/**
 * Far more than any rounding error of a distance computed here (grid coordinates are at most 63,
 * so under 1e-12 grid units), far less than the least max_error (0.001): what the reach of a
 * stroke (below) adds for rounding, so that it never understates a true distance, and the room
 * it keeps below max_error, so that no distance it lets through could compute above it.
 */
const ROUNDING_SLACK = 1e-9;

/** What `push` gives when no stroke is finished (most samples): one frozen array, none made. */
const NO_SEGMENTS: readonly Segment[] = Object.freeze([]);

/**
 * An index past every sample a store holds: `Drawn.base` or `Drawn.first` of a reader that is not
 * there. A small integer (the largest V8 keeps unboxed), not Infinity: an index field that once
 * held a double is read as one, and converted, wherever it indexes an array.
 */
const UNREAD = 0x3fffffff;

/**
 * The samples a store drops from its start once this many have gathered there (and they are at
 * least half): few enough that the arrays stay small (few regrowths for a simplifier made per
 * path), enough that each sample is moved at most once on average.
 */
const COMPACT_AFTER = 32;

/**
 * The samples drawn in a path, as flat arrays of numbers (grid x, grid y, time; arrays of doubles,
 * stored unboxed) and their Sample objects, kept from one path to the next and shared by the
 * window and the merger: every sample is stored once, where both read it. The stroke being drawn
 * is a range of them: its anchor is held apart (`WindowCore`: a cut's end or a moved time need
 * not be a drawn sample), window index i > 0 is sample `base` + i, and the samples after the
 * stroke, up to the store's `count`, are the ones still to take into it (after a cut, the samples
 * after the cut, taken again into the next stroke: the window moves on over them, nothing is
 * copied). Samples before the smaller of `base` and `first` (the merger's first not yet covered)
 * are needed by neither and are dropped now and then (`compact`).
 */
class Drawn {
  readonly xs: number[] = [];
  readonly ys: number[] = [];
  readonly ts: number[] = [];
  readonly samples: Sample[] = [];
  count = 0;
  /** The sample of the window's anchor (`UNREAD`: no window reads these samples). */
  base = UNREAD;
  /** The merger's first sample not yet covered (`UNREAD`: no merger reads these samples). */
  first = UNREAD;

  /** Drops the samples neither reader needs, once enough have gathered (`COMPACT_AFTER`). */
  compact(): void {
    const keep = Math.min(this.base, this.first);
    const count = this.count;
    if (!(keep >= COMPACT_AFTER && 2 * keep >= count)) return;
    const { xs, ys, ts, samples } = this;
    for (let from = keep, to = 0; from < count; from++, to++) {
      xs[to] = xs[from]!;
      ys[to] = ys[from]!;
      ts[to] = ts[from]!;
      samples[to] = samples[from]!;
    }
    this.count = count - keep;
    if (this.base !== UNREAD) this.base -= keep;
    if (this.first !== UNREAD) this.first -= keep;
  }
}

/**
 * The window itself: strokes cut by the error bound, the bend rule and the caps, before
 * too-short pieces are merged (`WindowSimplifier` merges them).
 */
export class WindowCore {
  readonly params: WindowParams;
  readonly #maxErrorSq: number;
  readonly #minLengthSq: number;
  /** The shortest piece the merger need not hold: the larger of floor_ms and min_duration_ms. */
  readonly #floorMs: number;
  readonly #mapping: CanvasMapping;
  /**
   * The mapping's terms (`CanvasMapping.gridX`, `gridY`), for `push` to map each sample itself
   * with the same operations: a call there is one too many to inline with the rest.
   */
  readonly #stretch: boolean;
  readonly #scale: number;
  readonly #offsetX: number;
  readonly #offsetY: number;
  readonly #widthPx: number;
  readonly #heightPx: number;
  /** The grid's extents (grid units): every stroke's start and end lies in [0, x] x [0, y]. */
  readonly #xExtent: number;
  readonly #yExtent: number;
  /** The samples drawn: the stroke being drawn is `#count` of them from `base` (`Drawn`). */
  readonly #drawn: Drawn;
  /** How many samples the stroke being drawn holds, its anchor included (0 between paths). */
  #count = 0;
  /**
   * The anchor, window[0]: where the stroke being drawn starts, when (a time a pen resting or
   * crawling moves on) and its Sample (canvas pixels, for `lineStart`): the drawn one, which
   * `lineStart` gives at `#anchorMs` when the anchor was retimed since (`#anchorRetimed`), made
   * only when asked rather than at every sample of a crawling pen.
   */
  #anchorX = 0;
  #anchorY = 0;
  #anchorMs = 0;
  #anchorSample: Sample | null = null;
  #anchorRetimed = false;
  /** Each sample's squared distance to a chord, while a cut looks for its feature. */
  readonly #distances: number[] = [];
  #emittedInPath = false;
  /**
   * The anchor as the point that ended the stroke before (null at a path's start): the next
   * stroke starts at that same point, a readonly pair, rather than at a copy made at every cut.
   */
  #anchor: Point | null = null;
  /**
   * The direction of the stroke the latency cap ended last (a unit vector), while the next one
   * may go on along it (`#hasLine`; not at a path's start nor after any other cut). Two numbers,
   * not a pair made at every cut.
   */
  #hasLine = false;
  #lineX = 0;
  #lineY = 0;
  /**
   * The reach of the stroke being drawn: no sample since its anchor lies farther than this from
   * the segment anchor -> last sample (grid units; true distances, rounding allowed for).
   * Moving the segment's end from E to E' moves no point of anchor -> E farther from
   * anchor -> E' than E itself lies from it (the distance to a segment is convex along a
   * segment, and 0 at the anchor), and that is at most the step E -> E', so when reach + that
   * distance stays under max_error (by ROUNDING_SLACK) every sample keeps the bound to the new
   * segment without testing each one, as testing each one would find; else they are tested, and
   * their farthest distance is the new reach. The same strokes, fewer tests: a pen going on along
   * its stroke adds little to the reach (its step, nearly all along the segment, moves it little).
   */
  #reach = 0;
  /** Reach + what a step adds at most this: every sample keeps the bound. */
  readonly #reachLimit: number;
  /**
   * The reach each sample of the stroke had when it was the last: a bound on the distances of
   * the samples before it to anchor -> it, which stay as they are while the stroke goes on. So
   * a test of window[1..i) against anchor -> window[i] or a point near it (a cut's feature, a
   * line's end) needs no sample tested when that bound says so.
   */
  readonly #reaches: number[] = [0]; // index 0 (the anchor) is never read; kept packed
  /** While the pen rests at the anchor (`rest_ms`): each sample near it moves the anchor's time. */
  #resting = false;
  /** Whether the last push found the pen resting (the stroke before the rest is final). */
  rested = false;
  /**
   * The last sample pushed, as taken: its time (never before the one before) and grid point. Three
   * numbers, not an object: it is read once per sample (`lastSample` makes the object if asked).
   */
  takenMs = 0;
  takenX = 0;
  takenY = 0;
  /** The squared rest radius (see `REST_SHARE`). */
  readonly #restSq: number;
  // The parameters `#follows` reads, read out of `params` once.
  readonly #capMs: number;
  readonly #restMs: number;
  readonly #maxWindow: number;
  /** Whether the bend rule is on (`max_bend` > 0): `#keepsBound` then tests with a limit of its own. */
  readonly #bends: boolean;
  /** `LINE_SHARE` x max_error, `STRAIGHT` x max_error, `CAP_FEATURE_SHARE` x max_stroke_ms. */
  readonly #lineLimit: number;
  readonly #straight: number;
  readonly #capFeatureMs: number;

  /** `drawn`: the store to keep the samples in, shared with a merger (else one of its own). */
  constructor(params: WindowParams, drawn: Drawn = new Drawn()) {
    checkWindowParams(params);
    this.params = params;
    this.#maxErrorSq = params.max_error * params.max_error;
    this.#minLengthSq = params.min_length * params.min_length;
    this.#floorMs = Math.max(params.floor_ms, params.min_duration_ms);
    this.#reachLimit = params.max_error - ROUNDING_SLACK;
    this.#xExtent = params.columns - 1;
    this.#yExtent = params.rows - 1;
    this.#mapping = CanvasMapping.fromParams(params);
    this.#stretch = params.stretch;
    this.#scale = this.#mapping.scale;
    this.#widthPx = params.canvas_width_px;
    this.#heightPx = params.canvas_height_px;
    this.#offsetX = (this.#xExtent - params.canvas_width_px * this.#scale) / 2;
    this.#offsetY = (this.#yExtent - params.canvas_height_px * this.#scale) / 2;
    const rest = restRadius(params, this.#mapping);
    this.#restSq = rest * rest;
    this.#capMs = params.max_stroke_ms;
    this.#restMs = params.rest_ms;
    this.#maxWindow = params.max_window;
    this.#bends = params.max_bend > 0;
    this.#lineLimit = LINE_SHARE * params.max_error;
    this.#straight = STRAIGHT * params.max_error;
    this.#capFeatureMs = CAP_FEATURE_SHARE * params.max_stroke_ms;
    this.#drawn = drawn;
  }

  /** True between the first sample of a path and `end`. */
  get drawing(): boolean {
    return this.#count > 0;
  }

  /** Where the stroke being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    if (this.#count === 0) return null;
    if (this.#anchorRetimed) {
      // Built field by field, not spread (the drawn sample may have more fields).
      const anchor = this.#anchorSample!;
      this.#anchorSample = { t_ms: this.#anchorMs, x: anchor.x, y: anchor.y, pressure: anchor.pressure };
      this.#anchorRetimed = false;
    }
    return this.#anchorSample;
  }

  /** The last sample taken, as taken: its time (never before the one before) and grid point. */
  lastSample(): { readonly t_ms: number; readonly point: Point } {
    return { t_ms: this.takenMs, point: [this.takenX, this.takenY] };
  }

  /** The time of the last sample pushed, as taken (0 before any). */
  pointerMs(): number {
    return this.takenMs;
  }

  // window[index] of the stroke being drawn, the anchor at 0 (for the tests made once a stroke).
  #xAt(index: number): number {
    return index === 0 ? this.#anchorX : this.#drawn.xs[this.#drawn.base + index]!;
  }

  #yAt(index: number): number {
    return index === 0 ? this.#anchorY : this.#drawn.ys[this.#drawn.base + index]!;
  }

  #msAt(index: number): number {
    return index === 0 ? this.#anchorMs : this.#drawn.ts[this.#drawn.base + index]!;
  }

  /** One pointer sample while the pointer is down; the first of a path is the press. */
  push(input: Sample): readonly Segment[] {
    const count = this.#count;
    if (count === 0) return this.#press(input);
    const drawn = this.#drawn;
    const last = drawn.base + count - 1;
    // Times never run backwards (two event sources' clocks): an earlier sample takes the last time.
    const lastMs = count > 1 ? drawn.ts[last]! : this.#anchorMs;
    let sample = input;
    let t = input.t_ms;
    if (t < lastMs) {
      sample = { ...input, t_ms: lastMs };
      t = lastMs;
    }
    // `CanvasMapping.gridX` and `gridY`, written out.
    const xPx = input.x;
    const yPx = input.y;
    const xExtent = this.#xExtent;
    const yExtent = this.#yExtent;
    const stretch = this.#stretch;
    const gridX = stretch ? (xPx * xExtent) / this.#widthPx : this.#offsetX + xPx * this.#scale;
    const gridY = stretch ? (yPx * yExtent) / this.#heightPx : this.#offsetY + yPx * this.#scale;
    const x = Math.min(Math.max(gridX, 0), xExtent);
    const y = Math.min(Math.max(gridY, 0), yExtent);
    this.takenMs = t;
    this.takenX = x;
    this.takenY = y;
    this.rested = false;
    // Stored after the others (written out here, not called: every sample runs this).
    const at = drawn.count;
    drawn.xs[at] = x;
    drawn.ys[at] = y;
    drawn.ts[at] = t;
    drawn.samples[at] = sample;
    drawn.count = at + 1;
    // `#follows`, written out (the same tests in the same order): most samples end here, and
    // whether the optimiser inlines a call here depends on what it inlined before, which made
    // the simplifier's speed differ by a third from one run to the next.
    if (!this.#resting && count >= 2 && count < this.#maxWindow && !this.#bends) {
      const sinceAnchorMs = t - this.#anchorMs;
      const capMs = this.#capMs;
      if (!(capMs > 0 && sinceAnchorMs > capMs)) {
        const lastX = drawn.xs[last]!;
        const lastY = drawn.ys[last]!;
        const ax = this.#anchorX;
        const ay = this.#anchorY;
        const dx = x - ax;
        const dy = y - ay;
        let qx = lastX - ax;
        let qy = lastY - ay;
        const lengthSq = dx * dx + dy * dy;
        if (lengthSq > 0) {
          const along = (qx * dx + qy * dy) / lengthSq;
          if (along >= 1) {
            qx = qx - dx;
            qy = qy - dy;
          } else if (!(along <= 0)) {
            qx = qx - along * dx;
            qy = qy - along * dy;
          }
        }
        const reach = this.#reach + Math.sqrt(qx * qx + qy * qy) + ROUNDING_SLACK;
        if (reach <= this.#reachLimit) {
          const restMs = this.#restMs;
          const sx = lastX - x;
          const sy = lastY - y;
          if (!(
            restMs > 0 &&
            sinceAnchorMs >= restMs &&
            sx * sx + sy * sy <= this.#restSq &&
            this.#restsAt(last, x, y, t)
          )) {
            this.#count = count + 1;
            this.#reach = reach;
            this.#reaches[count] = reach;
            return NO_SEGMENTS;
          }
        }
      }
    }
    return this.#add() ?? NO_SEGMENTS;
  }

  /** A path's first sample: the anchor of its first stroke, the first of the store. */
  #press(sample: Sample): readonly Segment[] {
    const t = sample.t_ms;
    const x = this.#mapping.gridX(sample.x);
    const y = this.#mapping.gridY(sample.y);
    this.takenMs = t;
    this.takenX = x;
    this.takenY = y;
    this.rested = false;
    const drawn = this.#drawn;
    drawn.xs[0] = x;
    drawn.ys[0] = y;
    drawn.ts[0] = t;
    drawn.samples[0] = sample;
    drawn.count = 1;
    drawn.base = 0;
    this.#anchorX = x;
    this.#anchorY = y;
    this.#anchorMs = t;
    this.#anchorSample = sample;
    this.#anchorRetimed = false;
    this.#count = 1;
    this.#reach = 0;
    this.#anchor = null;
    this.#emittedInPath = false;
    this.#hasLine = false;
    this.#resting = false;
    return NO_SEGMENTS;
  }

  /**
   * The common sample, taken at once if it is one: window[count] joins the stroke and cuts
   * nothing, as `#add` would find: the pen neither rests nor crawls, the stroke stays under the
   * caps, and its reach says every sample keeps the bound without testing one (the bend rule
   * off). Else (false) nothing has changed, and `#add` takes it. The same tests as `#add`'s, in a
   * short function for the optimiser to inline in `#add` (`push` has them written out).
   */
  #follows(count: number, x: number, y: number, t: number): boolean {
    if (this.#resting || count < 2 || count >= this.#maxWindow || this.#bends) return false;
    const sinceAnchorMs = t - this.#anchorMs;
    const capMs = this.#capMs;
    if (capMs > 0 && sinceAnchorMs > capMs) return false;
    const drawn = this.#drawn;
    const last = drawn.base + count - 1;
    const lastX = drawn.xs[last]!;
    const lastY = drawn.ys[last]!;
    // `stepReach`, written out with the same operations (`distanceSq`, `chordDistanceSq`).
    const ax = this.#anchorX;
    const ay = this.#anchorY;
    const dx = x - ax;
    const dy = y - ay;
    let qx = lastX - ax;
    let qy = lastY - ay;
    const lengthSq = dx * dx + dy * dy;
    if (lengthSq > 0) {
      const along = (qx * dx + qy * dy) / lengthSq;
      if (along >= 1) {
        qx = qx - dx;
        qy = qy - dy;
      } else if (!(along <= 0)) {
        qx = qx - along * dx;
        qy = qy - along * dy;
      }
    }
    const reach = this.#reach + Math.sqrt(qx * qx + qy * qy) + ROUNDING_SLACK;
    // `#keepsBound`'s shortcut.
    if (!(reach <= this.#reachLimit)) return false;
    // `#add`'s test for a pen that may rest, then whether it does (`#restsAt`): many samples of a
    // slow pen stay near the one before, few near every one of the last rest_ms.
    const restMs = this.#restMs;
    if (restMs > 0 && sinceAnchorMs >= restMs && squared(lastX - x, lastY - y) <= this.#restSq) {
      if (this.#restsAt(last, x, y, t)) return false;
    }
    this.#count = count + 1;
    this.#reach = reach;
    this.#reaches[count] = reach;
    return true;
  }

  /**
   * Whether the pen rests at (x, y), drawn at `t` after the store's sample `last`, which lies
   * within the rest radius of it (`#follows`, as `#rests` finds): every sample back to one drawn
   * rest_ms or more before lies within the rest radius of it.
   */
  #restsAt(last: number, x: number, y: number, t: number): boolean {
    const drawn = this.#drawn;
    const { xs, ys, ts } = drawn;
    const base = drawn.base;
    const restSq = this.#restSq;
    let start = last;
    while (start > base + 1 && squared(xs[start - 1]! - x, ys[start - 1]! - y) <= restSq) start--;
    const startMs =
      start === base + 1 && squared(this.#anchorX - x, this.#anchorY - y) <= restSq
        ? this.#anchorMs
        : ts[start]!;
    return !(t - startMs < this.#restMs);
  }

  /** Release: the rest of the path as one stroke (a tap gives one, dropped, of length 0). */
  end(): Segment[] {
    const count = this.#count;
    if (count === 0) return [];
    this.#count = 0;
    this.#resting = false;
    // The last sample already ends a stroke (a cut at the work cap).
    if (count === 1 && this.#emittedInPath) return [];
    const end = this.#continued(count - 1);
    return [this.#finish(this.#start(), this.#anchorMs, end, this.#msAt(count - 1))];
  }

  /**
   * The samples to take (the new one, after any a cut gave back) join the stroke being drawn in
   * order, each cutting it first where it must: the strokes they finish, or null if none (an
   * array made only when one is).
   */
  #add(): Segment[] | null {
    let out: Segment[] | null = null;
    const drawn = this.#drawn;
    const { xs, ys, ts } = drawn;
    const capMs = this.#capMs;
    const maxWindow = this.#maxWindow;
    const restMs = this.#restMs;
    for (let first = true; ; first = false) {
      const count = this.#count;
      const at = drawn.base + count;
      const x = xs[at]!;
      const y = ys[at]!;
      const t = ts[at]!;
      // Most samples a cut gives back are common ones too (`push` tried the new one).
      if (!first && this.#follows(count, x, y, t)) {
        if (drawn.base + this.#count === drawn.count) return out;
        continue;
      }
      if (this.#resting) {
        if (count === 1 && squared(x - this.#anchorX, y - this.#anchorY) <= this.#restSq) {
          // The pen still rests: the next stroke starts when it moves on, not before. The sample
          // is not taken: the window moves on past it (the merger still sees it).
          this.#retime(t);
          drawn.base++;
          if (drawn.base + this.#count === drawn.count) return out;
          continue;
        }
        this.#resting = false;
      }
      if (capMs > 0 && count > 1 && t - this.#anchorMs > capMs) {
        if (!this.#sendable(this.#anchorX, this.#anchorY, xs[at - 1]!, ys[at - 1]!)) {
          // The pen crawls: too little drawn in max_stroke_ms to send. The stroke starts later
          // rather than lasting longer, so the cap holds for it too.
          this.#retime(t - capMs);
        } else {
          const cut = this.#capCut(count);
          const vertex = this.#continued(cut);
          out = more(out, this.#finish(this.#start(), this.#anchorMs, vertex, this.#msAt(cut)));
          this.#lineOf(cut, vertex);
          // The samples after the cut, this one included, are taken again into the next stroke.
          this.#restart(vertex, cut);
          continue;
        }
      }
      if (!this.#keepsBound(count, x, y)) {
        let cut = this.#feature(count, x, y, 1);
        const floorEndMs = this.#anchorMs + this.#floorMs;
        const base = drawn.base;
        if (ts[base + cut]! < floorEndMs && floorEndMs <= ts[at - 1]!) {
          // The piece would be briefer than the sleeve's floor, and the window holds a longer
          // one: cut at the feature among the samples drawn at least the floor after the anchor
          // (the last one always keeps the bound), so the sleeve need not slow the piece and the
          // merger need not hold it.
          let later = cut + 1;
          while (ts[base + later]! < floorEndMs) later++;
          cut = this.#feature(count, x, y, later);
        }
        const end: Point = [xs[base + cut]!, ys[base + cut]!];
        out = more(out, this.#finish(this.#start(), this.#anchorMs, end, ts[base + cut]!));
        this.#hasLine = false;
        this.#restart(end, cut);
      } else {
        this.#count = count + 1;
        this.#reaches[count] = this.#reach;
        // A stroke younger than rest_ms cannot hold a rest, nor a pen that left the rest radius
        // since the sample before: most samples stop at these two tests.
        const rest =
          restMs > 0 &&
          t - this.#anchorMs >= restMs &&
          squared(this.#xAt(count - 1) - x, this.#yAt(count - 1) - y) <= this.#restSq
            ? this.#rests(count + 1)
            : false;
        if (rest !== false) {
          // The pen rests: the stroke before it, if any, is out; the anchor waits for the pen.
          if (rest !== null) out = more(out, rest);
        } else if (count >= maxWindow) {
          const end: Point = [x, y];
          out = more(out, this.#finish(this.#start(), this.#anchorMs, end, t));
          this.#hasLine = false;
          this.#restart(end, count);
        }
      }
      if (drawn.base + this.#count === drawn.count) return out;
    }
  }

  /** Where the stroke being drawn starts: its anchor, window[0]. */
  #start(): Point {
    return this.#anchor ?? [this.#anchorX, this.#anchorY];
  }

  /**
   * Only one sample in the stroke, its anchor at `anchor` with the time and Sample of
   * window[index] (index > 0), the samples after it to take again: nothing measured of the
   * stroke before holds for the next.
   */
  #restart(anchor: Point, index: number): void {
    const drawn = this.#drawn;
    const at = drawn.base + index;
    this.#anchorX = anchor[0];
    this.#anchorY = anchor[1];
    this.#anchorMs = drawn.ts[at]!;
    this.#anchorSample = drawn.samples[at]!;
    this.#anchorRetimed = false;
    drawn.base = at;
    this.#count = 1;
    this.#anchor = anchor;
    this.#reach = 0;
    drawn.compact();
  }

  /** The anchor at another time (while the pen rests or crawls), its Sample too (`lineStart`). */
  #retime(t: number): void {
    this.#anchorMs = t;
    this.#anchorRetimed = true;
  }

  /**
   * Where a rest at (x, y) begins: the least window index from which every sample up to
   * window[last] (itself not tested) lies within the rest radius of (x, y), walking back.
   */
  #restStart(last: number, x: number, y: number): number {
    const { xs, ys, base } = this.#drawn;
    const restSq = this.#restSq;
    let start = last;
    while (start > 1 && squared(xs[base + start - 1]! - x, ys[base + start - 1]! - y) <= restSq) start--;
    if (start === 1 && squared(this.#anchorX - x, this.#anchorY - y) <= restSq) start = 0;
    return start;
  }

  /**
   * Whether the pen has rested `rest_ms` at the stroke's newest sample, window[count - 1].
   *
   * It rests when its samples of the last `rest_ms` or more all lie within the rest radius of
   * that sample. The stroke drawn up to the rest then ends there at the time the rest began, and
   * is sent now (returned; null if the stroke is all rest, false if the pen does not rest); the
   * rest is not played (the next stroke starts where and when the
   * pen moves on). If the stroke is all rest, its anchor waits instead. Every sample of the rest
   * lies within the rest radius (at most max_error / 2) of the newest, and that one within it of
   * the anchor when all is rest.
   */
  #rests(count: number): Segment | null | false {
    const restMs = this.#restMs;
    const last = count - 1;
    const t = this.#msAt(last);
    if (restMs <= 0 || t - this.#anchorMs < restMs) return false;
    const x = this.#xAt(last);
    const y = this.#yAt(last);
    const start = this.#restStart(last, x, y);
    if (t - this.#msAt(start) < restMs) return false;
    let stroke: Segment | null = null;
    if (start === 0) {
      const anchor = this.#anchorSample;
      this.#restart(this.#start(), last);
      this.#anchorSample = anchor;
      this.#retime(t);
    } else {
      const end: Point = [x, y];
      stroke = this.#finish(this.#start(), this.#anchorMs, end, this.#msAt(start));
      this.#restart(end, last);
    }
    this.#hasLine = false;
    this.#resting = true;
    this.rested = true;
    return stroke;
  }

  /**
   * Whether every sample since the anchor (window[1..count)) lies within max_error of
   * anchor -> (x, y), as `#within` finds; sets the reach for (x, y) as the stroke's new last
   * sample. A NaN drawn is never farther than max_error (no comparison with NaN is true), in
   * `#within` as here: a NaN step tests every sample, a NaN sample counts in no reach.
   */
  #keepsBound(count: number, x: number, y: number): boolean {
    if (count === 1) {
      this.#reach = 0;
      return true;
    }
    const drawn = this.#drawn;
    const ax = this.#anchorX;
    const ay = this.#anchorY;
    let reachLimit = this.#reachLimit;
    let limitSq = this.#maxErrorSq;
    const bend = this.params.max_bend;
    if (bend > 0) {
      // The bend rule: a round shape is cut before its chord strays farther than a share of the
      // chord's length, never under the floor, never over max_error.
      const cx = x - ax;
      const cy = y - ay;
      const limit = Math.max(bend * Math.sqrt(cx * cx + cy * cy), this.params.bend_floor);
      if (limit < this.params.max_error) {
        reachLimit = limit - ROUNDING_SLACK;
        limitSq = limit * limit;
      }
    }
    const last = drawn.base + count - 1;
    const reach = this.#reach + stepReach(ax, ay, drawn.xs[last]!, drawn.ys[last]!, x, y) + ROUNDING_SLACK;
    if (reach <= reachLimit) {
      this.#reach = reach;
      return true;
    }
    const farthestSq = this.#farthestSq(count, x, y, limitSq);
    if (farthestSq < 0) return false;
    this.#reach = Math.sqrt(farthestSq) + ROUNDING_SLACK;
    return true;
  }

  /**
   * Whether window[1..index] surely lie within `limit` + ROUNDING_SLACK of anchor -> (endX, endY),
   * a point near window[index], by its reach (moving the end moves the segment at most as far):
   * then a test of each finds them all within. False when unsure (a NaN too): test each.
   */
  #reachesNear(index: number, endX: number, endY: number, limit: number): boolean {
    const dx = endX - this.#xAt(index);
    const dy = endY - this.#yAt(index);
    return this.#reaches[index]! + Math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK <= limit;
  }

  /**
   * Where the latency cap cuts: at a feature in the stroke's later part, else at
   * its end. The feature is the sample farthest from the chord anchor -> last
   * sample among those drawn at least `CAP_FEATURE_SHARE` x max_stroke_ms after
   * the anchor whose own stroke keeps the bound and is long enough to send; if it
   * lies on the chord (a straight stroke, to `STRAIGHT`), at the last sample.
   */
  #capCut(count: number): number {
    const { xs, ys, ts, base } = this.#drawn;
    const last = count - 1;
    const earliest = this.#anchorMs + this.#capFeatureMs;
    let first = 1;
    while (first < last && ts[base + first]! < earliest) first++;
    const lastX = xs[base + last]!;
    const lastY = ys[base + last]!;
    const cut = this.#feature(count, lastX, lastY, first);
    const straight = this.#straight;
    const ax = this.#anchorX;
    const ay = this.#anchorY;
    const cutX = xs[base + cut]!;
    const cutY = ys[base + cut]!;
    const farSq = distanceSq(cutX, cutY, ax, ay, lastX, lastY);
    const bends = farSq > straight * straight;
    return bends && this.#sendable(ax, ay, cutX, cutY) ? cut : last;
  }

  /**
   * Where a stroke that the latency cap or the release ends, ending at window[cut], ends
   * (at window[cut]'s time).
   * After a stroke the latency cap ended, the stroke that follows it goes on along the same
   * line when it can: its end is window[cut] projected onto that line, if it lies on the grid
   * (the sleeve refuses a stroke off it), every sample up to window[cut] keeps the bound to the
   * projected end and the stroke is still long enough to send; else window[cut] itself. The
   * cap cuts a drawn line, not a drawn corner, so a straight line cut into strokes stays one
   * straight line.
   */
  #continued(cut: number): Point {
    const atX = this.#xAt(cut);
    const atY = this.#yAt(cut);
    if (!this.#hasLine) return [atX, atY];
    const ux = this.#lineX;
    const uy = this.#lineY;
    const ax = this.#anchorX;
    const ay = this.#anchorY;
    const along = (atX - ax) * ux + (atY - ay) * uy;
    if (along <= 0) return [atX, atY];
    const endX = ax + along * ux;
    const endY = ay + along * uy;
    // On the line but off the grid (a line drawn along an edge, its noise clamped onto the
    // edge): the sleeve refuses a stroke that ends off the grid, so keep the drawn sample, which
    // the mapping put on it. Not the projection clamped: that would bend the line.
    if (!(0 <= endX && endX <= this.#xExtent && 0 <= endY && endY <= this.#yExtent)) {
      return [atX, atY];
    }
    const limit = this.#lineLimit;
    // A bend, not noise.
    if (distanceSq(atX, atY, endX, endY, endX, endY) > limit * limit) return [atX, atY];
    if (
      !this.#sendable(ax, ay, endX, endY) ||
      !(
        this.#reachesNear(cut, endX, endY, this.#reachLimit) ||
        this.#within(cut + 1, endX, endY, this.#maxErrorSq)
      )
    ) {
      return [atX, atY];
    }
    return [endX, endY];
  }

  /**
   * The line the next stroke may go on along (`#hasLine`, `#lineX`, `#lineY`): the direction of
   * the stroke window[0] -> end if it is a line (every sample up to window[cut] within
   * `LINE_SHARE` x max_error of it) of some length, else none.
   */
  #lineOf(cut: number, end: Point): void {
    this.#hasLine = false;
    const endX = end[0];
    const endY = end[1];
    const limit = this.#lineLimit;
    const certain = this.#reachesNear(cut, endX, endY, limit - ROUNDING_SLACK);
    if (!certain && !this.#within(cut + 1, endX, endY, limit * limit)) return;
    const dx = endX - this.#anchorX;
    const dy = endY - this.#anchorY;
    const length = Math.sqrt(dx * dx + dy * dy);
    if (!(length > 0)) return;
    this.#lineX = dx / length;
    this.#lineY = dy / length;
    this.#hasLine = true;
  }

  /** Whether start -> end is long enough to send (the cap never cuts off a dropped stroke). */
  #sendable(startX: number, startY: number, endX: number, endY: number): boolean {
    const dx = endX - startX;
    const dy = endY - startY;
    return dx * dx + dy * dy >= this.#minLengthSq;
  }

  /**
   * Where to cut: the sample farthest from anchor -> end whose own stroke keeps
   * the bound (the last sample always does). Ties go to the later sample.
   */
  #feature(count: number, endX: number, endY: number, first: number): number {
    const { xs, ys, base } = this.#drawn;
    const distances = this.#distances;
    const ax = this.#anchorX;
    const ay = this.#anchorY;
    let finite = true;
    // The farthest, found as the distances are: nearly always the cut, so no second pass.
    let farthest = -1;
    let farthestDistance = -1;
    // The chord's terms computed once, as in `#farthestSq`.
    const dx = endX - ax;
    const dy = endY - ay;
    const lengthSq = dx * dx + dy * dy;
    for (let i = first; i < count; i++) {
      const qx = xs[base + i]! - ax;
      const qy = ys[base + i]! - ay;
      const d = lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
      distances[i] = d;
      if (Number.isNaN(d)) finite = false;
      else if (d >= farthestDistance) {
        farthestDistance = d;
        farthest = i;
      }
    }
    if (!finite) return this.#featureSorted(count, first);
    if (farthest < 0) return count - 1; // unreachable: the last sample fits by construction
    if (this.#fits(farthest)) return farthest;
    distances[farthest] = -1;
    // Farthest first and, at equal distances, the later sample first: the order of a sort by
    // (distance, index) descending, taken one at a time since the farthest nearly always fits.
    // Distances are >= 0, so -1 marks a sample tried.
    for (;;) {
      let best = -1;
      let bestDistance = -1;
      for (let i = count - 1; i >= first; i--) {
        if (distances[i]! > bestDistance) {
          bestDistance = distances[i]!;
          best = i;
        }
      }
      if (best < 0) return count - 1; // unreachable: the last sample fits by construction
      if (this.#fits(best)) return best;
      distances[best] = -1;
    }
  }

  /**
   * `#feature` for distances that are not all numbers (a NaN drawn): the candidates in the order
   * of a sort with the same comparator, which a NaN makes inconsistent, so the sort itself.
   */
  #featureSorted(count: number, first: number): number {
    const ranked: { index: number; distanceSq: number }[] = [];
    for (let i = first; i < count; i++) ranked.push({ index: i, distanceSq: this.#distances[i]! });
    ranked.sort((a, b) => b.distanceSq - a.distanceSq || b.index - a.index);
    for (const { index } of ranked) {
      if (this.#fits(index)) return index;
    }
    return count - 1; // unreachable: the last sample fits by construction
  }

  /** Whether window[index] can end the stroke: every sample before it within the bound of its own chord. */
  #fits(index: number): boolean {
    return (
      this.#reaches[index]! <= this.#reachLimit ||
      this.#within(index, this.#xAt(index), this.#yAt(index), this.#maxErrorSq)
    );
  }

  /** Whether window[1..stop) all lie within sqrt(limitSq) of window[0] -> (endX, endY). */
  #within(stop: number, endX: number, endY: number, limitSq: number): boolean {
    return this.#farthestSq(stop, endX, endY, limitSq) >= 0;
  }

  /**
   * The greatest squared distance of window[1..stop) to window[0] -> (endX, endY) (0 if none,
   * NaN counting as none), or -1 as soon as one exceeds limitSq: the inner loop of every
   * sample: its chord terms computed once (`chordDistanceSq`).
   */
  #farthestSq(stop: number, endX: number, endY: number, limitSq: number): number {
    const { xs, ys, base } = this.#drawn;
    const ax = this.#anchorX;
    const ay = this.#anchorY;
    const dx = endX - ax;
    const dy = endY - ay;
    const lengthSq = dx * dx + dy * dy;
    let farthest = 0;
    const last = base + stop;
    if (lengthSq > 0) {
      for (let i = base + 1; i < last; i++) {
        const d = chordDistanceSq(xs[i]! - ax, ys[i]! - ay, dx, dy, lengthSq);
        if (d > limitSq) return -1;
        if (d > farthest) farthest = d;
      }
    } else {
      for (let i = base + 1; i < last; i++) {
        const qx = xs[i]! - ax;
        const qy = ys[i]! - ay;
        const d = qx * qx + qy * qy;
        if (d > limitSq) return -1;
        if (d > farthest) farthest = d;
      }
    }
    return farthest;
  }

  #finish(start: Point, startMs: number, end: Point, endMs: number): Segment {
    this.#emittedInPath = true;
    return finishSegment(start, end, startMs, endMs, this.takenMs, this.params);
  }
}

/**
 * Merges the pieces the window cuts too short to send into a neighbour, never dropping one (the
 * reference's `Merger`). A piece is too short when it is shorter than `min_length` or briefer
 * than the larger of `min_duration_ms` and `floor_ms` (the sleeve would slow it). A short piece
 * waits for the next; the two become one stroke when every drawn sample of both lies within
 * `max_error` of it (still short, it waits again), else the short one is sent as it is. A piece
 * long enough is sent at once (holding each back would delay the drawing), so the last piece of
 * a path, if short, is sent short, unless at release it is briefer than the floor and lies, with
 * every drawn sample not yet covered, within `max_error` of the stroke already sent before it:
 * then it merges into that stroke and nothing more is sent (`mergedBack`). Only a path's one and
 * only piece, too short, is dropped. With strict minimums (a wearer's), a piece below them merges
 * into the next whatever the bound, but never across a rest (`rest`), and one left at release or
 * at a rest merges back where the bound allows, else is dropped with its reason.
 */
export class Merger {
  readonly #maxError: number;
  readonly #minLength: number;
  readonly #minDurationMs: number;
  readonly #shortMs: number;
  readonly #strict: boolean;
  /**
   * Whether a piece too short or too brief waits to merge (the window's pieces). The least
   * squares' pieces do not, unless strict: they are briefer than the floor only where no piece
   * lasting it keeps the bound, and one that lasts the floor yet is shorter than min_length was
   * drawn by a nearly still pen; each is sent as it is, a brief one to last the floor.
   */
  readonly #holdShort: boolean;
  /**
   * With holdShort off (the least squares' pieces): no merge makes a stroke outlast this (the
   * latency cap, ms; 0: no limit). The window's own merges keep it by their pieces.
   */
  readonly #capMs: number;
  /**
   * The drawn samples (ms, grid units), oldest first: those not yet covered by a sent stroke are
   * [first, count) (`Drawn`). The window's own store when the merger takes its pieces (each
   * sample stored once), else one of its own that `sample` fills. Not a typed array: its buffer
   * lives outside the heap and is zeroed when made, which cost more than its samples for a
   * simplifier made per path (as the bench makes one per demonstration).
   */
  readonly #drawn: Drawn;
  #held: Segment | null = null;
  #sentInPath = false;
  /**
   * The path's last sent stroke (null before its first): a piece briefer than the sleeve's floor
   * left at release merges into it when every drawn sample it has not covered lies within
   * max_error of it (`end`).
   */
  #last: Segment | null = null;
  /**
   * Pieces merged at release (or, strict, at a rest) into a stroke already sent (nothing more is
   * sent for them), in all.
   */
  mergedBack = 0;

  constructor(
    maxError: number,
    minLength: number,
    minDurationMs: number,
    floorMs: number,
    strict = false,
    holdShort = true,
    capMs = 0,
    drawn: Drawn = new Drawn(),
  ) {
    this.#drawn = drawn;
    drawn.first = 0;
    this.#maxError = maxError;
    this.#minLength = minLength;
    this.#minDurationMs = minDurationMs;
    this.#shortMs = Math.max(minDurationMs, floorMs);
    this.#strict = strict;
    this.#holdShort = holdShort;
    this.#capMs = capMs;
  }

  /** A drawn sample, in order (its time as the window took it). */
  sample(tMs: number, x: number, y: number): void {
    const drawn = this.#drawn;
    const at = drawn.count;
    drawn.xs[at] = x;
    drawn.ys[at] = y;
    drawn.ts[at] = tMs;
    drawn.count = at + 1;
  }

  #short(segment: Segment): boolean {
    // A path's first piece waits even where the least squares send pieces as they are: a tap is
    // dropped.
    return (
      (this.#holdShort || !this.#sentInPath) &&
      (segmentLength(segment) < this.#minLength || segment.duration_ms < this.#shortMs)
    );
  }

  #belowMinimums(segment: Segment): boolean {
    return segmentLength(segment) < this.#minLength || segment.duration_ms < this.#minDurationMs;
  }

  /**
   * Whether every sample not yet covered, drawn up to endMs, lies within max_error of
   * start -> end. All of them, not only those after the held piece's start: a stroke whose pen
   * crawled or rested starts after samples it covers.
   */
  #fits(start: Point, end: Point, endMs: number): boolean {
    const limitSq = this.#maxError * this.#maxError;
    const { xs, ys, ts, count } = this.#drawn;
    // `distanceSq` with the chord's terms computed once (the same operations, as in `#farthestSq`).
    const ax = start[0];
    const ay = start[1];
    const dx = end[0] - ax;
    const dy = end[1] - ay;
    const lengthSq = dx * dx + dy * dy;
    for (let i = this.#drawn.first; i < count; i++) {
      if (ts[i]! > endMs) break;
      const qx = xs[i]! - ax;
      const qy = ys[i]! - ay;
      const d = lengthSq > 0 ? chordDistanceSq(qx, qy, dx, dy, lengthSq) : qx * qx + qy * qy;
      if (d > limitSq) return false;
    }
    return true;
  }

  #send(segment: Segment, nowMs: number, out: Segment[]): void {
    out.push(this.#sent(segment, nowMs));
  }

  /** `#send` without the array: the stroke to send, as `#send` gives it. */
  #sent(segment: Segment, nowMs: number): Segment {
    this.#sentInPath = true;
    this.#last = segment;
    // A piece made at this sample and not dropped (most: the window's and the merged ones) is sent
    // as it is; else a copy, built field by field, not spread (several times slower): the same
    // keys in the same order. Object.is: -0 and 0 are different times to the vectors.
    // A stroke drawn briefer than the sleeve's floor (one that could not merge) lasts the floor:
    // the sleeve would slow it to that, and has nothing to adjust (its times stay the drawn ones).
    const shortMs = this.#shortMs;
    const durationMs = segment.end_ms - segment.start_ms < shortMs ? shortMs : segment.duration_ms;
    const sent: Segment =
      segment.dropped === null &&
      Object.is(segment.emitted_at_ms, nowMs) &&
      durationMs === segment.duration_ms
        ? segment
        : segment.merged === undefined
          ? {
              start: segment.start,
              end: segment.end,
              start_ms: segment.start_ms,
              end_ms: segment.end_ms,
              duration_ms: durationMs,
              emitted_at_ms: nowMs,
              dropped: null,
            }
          : {
              start: segment.start,
              end: segment.end,
              start_ms: segment.start_ms,
              end_ms: segment.end_ms,
              duration_ms: durationMs,
              emitted_at_ms: nowMs,
              dropped: null,
              merged: segment.merged,
            };
    // The samples before its end are covered now (those at its end may start the next).
    const drawn = this.#drawn;
    const { ts, count } = drawn;
    const endMs = segment.end_ms;
    let keep = drawn.first;
    while (keep < count && ts[keep]! < endMs) keep++;
    drawn.first = keep;
    drawn.compact();
    return sent;
  }

  /** A piece the window cut: the strokes sent now, into `out` (none while a short one waits). */
  take(input: Segment, nowMs: number, out: Segment[]): void {
    let piece = input;
    const held = this.#held;
    if (held !== null) {
      this.#held = null;
      const withinCap = this.#holdShort || this.#capMs <= 0 || piece.end_ms - held.start_ms <= this.#capMs;
      if (
        (withinCap && this.#fits(held.start, piece.end, piece.end_ms)) ||
        (this.#strict && this.#belowMinimums(held))
      ) {
        piece = {
          start: held.start,
          end: piece.end,
          start_ms: held.start_ms,
          end_ms: piece.end_ms,
          duration_ms: piece.end_ms - held.start_ms,
          emitted_at_ms: nowMs,
          dropped: null,
          merged: (held.merged ?? 0) + (piece.merged ?? 0) + 1,
        };
      } else {
        this.#send(held, nowMs, out);
      }
    }
    if (this.#short(piece)) this.#held = piece;
    else this.#send(piece, nowMs, out);
  }

  /**
   * `take` for a piece the window cut alone, in `pieces` (an array of one, made for it): the
   * strokes sent now, in that same array when it is one (most pieces: none held, none short),
   * else in another (`NO_SEGMENTS` if none).
   */
  takeAlone(pieces: Segment[], nowMs: number): readonly Segment[] {
    const piece = pieces[0]!;
    if (this.#held === null) {
      if (this.#short(piece)) {
        this.#held = piece;
        return NO_SEGMENTS;
      }
      pieces[0] = this.#sent(piece, nowMs);
      return pieces;
    }
    pieces.pop();
    this.take(piece, nowMs, pieces);
    return pieces.length > 0 ? pieces : NO_SEGMENTS;
  }

  /**
   * The pen rests (since the held piece's end, until `nowMs`): the held piece is let go now, into
   * `out`, rather than merged with what comes after the rest, which would play the rest. If it is
   * briefer than the sleeve's floor, it takes the time it needs from the rest: the pen was at its
   * end then, and it is sent. With strict minimums, a piece still below them is not sent: as at
   * release, it merges into the path's last sent stroke where that keeps the bound
   * (`#mergesBack`), else it is dropped with its reason.
   */
  rest(nowMs: number, out: Segment[]): void {
    let held = this.#held;
    if (held === null) return;
    if (held.duration_ms < this.#shortMs && nowMs > held.end_ms) {
      const endMs = Math.min(floorEndMs(held.start_ms, this.#shortMs), nowMs);
      held = { ...held, end_ms: endMs, duration_ms: endMs - held.start_ms };
    }
    this.#held = null;
    if (this.#strict && this.#belowMinimums(held)) {
      if (this.#mergesBack(held)) this.mergedBack += (held.merged ?? 0) + 1;
      else out.push({ ...held, emitted_at_ms: nowMs, dropped: this.#reason(held) });
      // Its samples are let go with it (those at its end may start the next).
      const drawn = this.#drawn;
      const { ts, count } = drawn;
      let keep = drawn.first;
      while (keep < count && ts[keep]! < held.end_ms) keep++;
      drawn.first = keep;
      drawn.compact();
      return;
    }
    this.#send(held, nowMs, out);
  }

  /** Why `segment` is too short to send (null if it is not). */
  #reason(segment: Segment): DropReason | null {
    if (segmentLength(segment) < this.#minLength) return NOT_ENOUGH_DISTANCE;
    if (segment.duration_ms < this.#minDurationMs) return NOT_ENOUGH_DURATION;
    return null;
  }

  /**
   * Whether the piece held at release merges into the path's last sent stroke: it is briefer
   * than the sleeve's floor (or, with strict minimums, shorter than min_length: it would be
   * dropped), and every drawn sample not yet covered lies within max_error of that stroke.
   */
  #mergesBack(held: Segment): boolean {
    const last = this.#last;
    if (last === null) return false;
    if (!(held.duration_ms < this.#shortMs || (this.#strict && segmentLength(held) < this.#minLength))) {
      return false;
    }
    return this.#fits(last.start, last.end, Infinity);
  }

  /**
   * Release, after the window's last piece: the held piece merges into the path's last sent
   * stroke where that keeps the bound (`#mergesBack`: nothing more is sent), else it is sent (or,
   * a path's only piece too short, dropped).
   */
  end(nowMs: number, out: Segment[]): void {
    let held = this.#held;
    if (held !== null && this.#mergesBack(held)) {
      this.mergedBack += (held.merged ?? 0) + 1;
      held = null;
    }
    if (held !== null) {
      const reason = !this.#sentInPath || this.#strict ? this.#reason(held) : null;
      if (reason !== null) out.push({ ...held, emitted_at_ms: nowMs, dropped: reason });
      else this.#send(held, nowMs, out);
    }
    this.#held = null;
    this.#sentInPath = false;
    this.#last = null;
    this.#drawn.count = 0;
    this.#drawn.first = 0;
  }
}

/**
 * The window simplifier: the window's pieces, the too-short ones merged (`Merger`). With
 * `least_squares` on, the pieces are the least-squares core's (`FitCore`), which the merger sends
 * as they are (a brief one to last the floor) unless strict minimums hold them.
 */
export class WindowSimplifier {
  readonly params: WindowParams;
  /** The window (null with `least_squares` on). */
  readonly #core: WindowCore | null;
  /** The least-squares core (null with `least_squares` off). */
  readonly #fit: FitCore | null;
  readonly #merger: Merger;
  readonly #restMs: number;
  /** The last sample pushed in the path being drawn (null between paths). */
  #last: Sample | null = null;

  constructor(params: WindowParams) {
    this.params = params;
    this.#restMs = params.rest_ms;
    if (params.least_squares) {
      // The core keeps its samples apart; the merger is given each one taken (`#pushFit`).
      this.#core = null;
      this.#fit = new FitCore(params);
      this.#merger = new Merger(
        params.max_error,
        params.min_length,
        params.min_duration_ms,
        params.floor_ms,
        params.strict_minimums,
        params.strict_minimums,
        params.max_stroke_ms,
      );
      return;
    }
    // One store of the drawn samples, which the window fills and the merger reads too.
    const drawn = new Drawn();
    this.#core = new WindowCore(params, drawn);
    this.#fit = null;
    this.#merger = new Merger(
      params.max_error,
      params.min_length,
      params.min_duration_ms,
      params.floor_ms,
      params.strict_minimums,
      true,
      0,
      drawn,
    );
  }

  /** True between the first sample of a path and `end`. */
  get drawing(): boolean {
    const fit = this.#fit;
    return fit !== null ? fit.drawing : this.#core!.drawing;
  }

  /** Where the stroke being drawn starts (canvas pixels), for showing it; null between paths. */
  get lineStart(): Sample | null {
    const fit = this.#fit;
    return fit !== null ? fit.lineStart : this.#core!.lineStart;
  }

  /**
   * One pointer sample while the pointer is down; the first of a path is the press.
   *
   * A sample `rest_ms` or more after the one before (with the rest rule on) comes after a stop: a
   * pointer held still sends no event, and a source that does not sample it where it is (the page
   * does, every 32 ms: `ui/pointer.ts`) leaves a gap. The pen is taken to have stood at the sample
   * before until this one, as if sampled there at this one's time: the rest rule sees the rest,
   * and the stop is not played as a stroke as long as the stop. Python `WindowSimplifier.push`.
   */
  push(input: Sample): readonly Segment[] {
    const last = this.#last;
    this.#last = input;
    const still = last === null ? null : stillBefore(last, input, this.#pointerMs(), this.#restMs);
    if (still !== null) {
      const before = this.#pushOne(still);
      const after = this.#pushOne(input);
      return before.length === 0 ? after : after.length === 0 ? before : [...before, ...after];
    }
    return this.#pushOne(input);
  }

  #pointerMs(): number {
    const fit = this.#fit;
    return fit !== null ? fit.pointerMs() : this.#core!.pointerMs();
  }

  #pushOne(input: Sample): readonly Segment[] {
    const fit = this.#fit;
    if (fit !== null) return this.#pushFit(fit, input);
    const core = this.#core!;
    const pieces = core.push(input);
    const merger = this.#merger;
    const takenMs = core.takenMs;
    // Most samples finish no piece: nothing to merge, no array made.
    if (pieces.length === 0 && !core.rested) return NO_SEGMENTS;
    // Most of the rest finish one: the window's array (made for it, of one slot) holds what
    // the merger sends instead, most often that piece itself: no other array made.
    if (pieces.length === 1 && !core.rested) return merger.takeAlone(pieces as Segment[], takenMs);
    const out: Segment[] = [];
    // Indexed, no iterator made: this runs at every stroke.
    for (let i = 0; i < pieces.length; i++) merger.take(pieces[i]!, takenMs, out);
    if (core.rested) merger.rest(takenMs, out);
    return out.length > 0 ? out : NO_SEGMENTS;
  }

  /** `push` with the least-squares core: the merger is given the sample taken, then its pieces. */
  #pushFit(fit: FitCore, input: Sample): readonly Segment[] {
    const pieces = fit.push(input);
    const merger = this.#merger;
    const takenMs = fit.takenMs;
    merger.sample(takenMs, fit.takenX, fit.takenY);
    if (pieces.length === 0 && !fit.rested) return NO_SEGMENTS;
    const out: Segment[] = [];
    for (let i = 0; i < pieces.length; i++) merger.take(pieces[i]!, takenMs, out);
    if (fit.rested) merger.rest(takenMs, out);
    return out.length > 0 ? out : NO_SEGMENTS;
  }

  /**
   * Pieces merged at release (or, strict, at a rest) into a stroke already sent (`Merger.end`,
   * `Merger.rest`), over every path so far.
   */
  get mergedBack(): number {
    return this.#merger.mergedBack;
  }

  /** Release: the rest of the path, the held piece first (a tap gives one, dropped). */
  end(): Segment[] {
    this.#last = null;
    const fit = this.#fit;
    const core = fit !== null ? fit : this.#core!;
    const nowMs = core.pointerMs();
    const out: Segment[] = [];
    const pieces = core.end();
    for (let i = 0; i < pieces.length; i++) this.#merger.take(pieces[i]!, nowMs, out);
    this.#merger.end(nowMs, out);
    return out;
  }
}

/**
 * The pen standing at `last` at `sample`'s time, where `sample` comes `restMs` or more after the
 * last time taken (`takenMs`: times never run backwards) with the rest rule on; else null
 * (`WindowSimplifier.push`). Python `still_before`.
 */
export function stillBefore(last: Sample, sample: Sample, takenMs: number, restMs: number): Sample | null {
  if (restMs > 0 && sample.t_ms - takenMs >= restMs) {
    return { t_ms: sample.t_ms, x: last.x, y: last.y, pressure: last.pressure };
  }
  return null;
}

/**
 * The samples `WindowSimplifier` takes for one path's `samples`: each, after the pen standing at
 * the one before where a stop left a gap (`stillBefore`). What its strokes cover, for tests and
 * tools that check them against the samples. Python `taken_samples`.
 */
export function takenSamples(samples: readonly Sample[], restMs: number): Sample[] {
  const taken: Sample[] = [];
  let takenMs = -Infinity;
  for (const sample of samples) {
    const still = taken.length > 0 ? stillBefore(taken[taken.length - 1]!, sample, takenMs, restMs) : null;
    if (still !== null) taken.push(still);
    taken.push(sample);
    takenMs = Math.max(takenMs, sample.t_ms);
  }
  return taken;
}

/**
 * The earliest end a piece starting at `startMs` lasts `floorMs` to: `startMs + floorMs`, or the
 * double above it where that sum rounds down (15000.1 + 73.701 - 15000.1 is 73.70099999999911,
 * which the sleeve would slow to 73.701 and report `adjusted`). Python `floor_end_ms`.
 */
export function floorEndMs(startMs: number, floorMs: number): number {
  let endMs = startMs + floorMs;
  while (endMs - startMs < floorMs) endMs = nextUp(endMs);
  return endMs;
}

const NEXT_UP = new Float64Array(1);
const NEXT_UP_BITS = new BigInt64Array(NEXT_UP.buffer);

/** The least double above `value` (finite), as Python's math.nextafter(value, inf). */
function nextUp(value: number): number {
  if (value === 0) return Number.MIN_VALUE;
  NEXT_UP[0] = value;
  NEXT_UP_BITS[0] = NEXT_UP_BITS[0]! + (value > 0 ? 1n : -1n);
  return NEXT_UP[0]!;
}

/**
 * `out` with `segment` after its others, `out` made if null: an array of one slot (`[]` then
 * push would reserve many), since most samples that finish a stroke finish one.
 */
function more(out: Segment[] | null, segment: Segment): Segment[] {
  if (out === null) return [segment];
  out.push(segment);
  return out;
}

function squared(dx: number, dy: number): number {
  return dx * dx + dy * dy;
}

/**
 * What moving the end of anchor -> (lastX, lastY) to (x, y) adds at most to the distance of any
 * point to it (`WindowCore`'s reach): the distance of (lastX, lastY) to anchor -> (x, y), never
 * more than the step between them, much less when the step goes on along the segment.
 */
function stepReach(ax: number, ay: number, lastX: number, lastY: number, x: number, y: number): number {
  return Math.sqrt(distanceSq(lastX, lastY, ax, ay, x, y));
}
