/**
 * A drawing: the paths drawn until the canvas is cleared, what the simplifier
 * made of them, and the strokes sent. Pure data; the page and the recording
 * read it. `seq` counts the sent strokes of one drawing from 0, so the sleeve
 * can order, deduplicate and chain them.
 */
import type { Stroke } from "./protocol";
import type { SimplifierParams } from "./simplify/registry";
import type { Sample, Segment } from "./simplify/segment";

export type PointerKind = "mouse" | "pen" | "touch";
/** Why a stroke sent for a segment was not felt. */
export type Unfelt = "refused" | "cancelled" | "unsent";

/** A segment of path `path`, and the stroke sent for it (null when dropped). */
export interface DrawnSegment {
  /** Position in `Drawing.segments`. */
  readonly index: number;
  readonly path: number;
  readonly segment: Segment;
  readonly stroke: Stroke | null;
}

/** A stroke sent lasting longer than it took to draw: drawn briefer than the sleeve's floor. */
function lengthened({ segment, stroke }: DrawnSegment): boolean {
  return stroke !== null && stroke.duration_ms > segment.end_ms - segment.start_ms;
}

export class Drawing {
  readonly id: string;
  /** The parameters every path of this drawing is simplified with (canvas size included). */
  readonly params: SimplifierParams;
  /** Pointer samples per path, as the pointer events reported them (the recording). */
  readonly paths: Sample[][] = [];
  /** The animation frames fed to the simplifier, per path. */
  readonly frames: Sample[][] = [];
  readonly pointerKinds: PointerKind[] = [];
  readonly segments: DrawnSegment[] = [];
  readonly #bySeq = new Map<number, DrawnSegment>();
  readonly #acked = new Set<number>();
  /** Strokes not felt, and why: refused by the sleeve, cancelled by Stop, or never sent. */
  readonly #refused = new Map<number, Unfelt>();
  /** Strokes kept on the page, not sent, while the wearer paused the sleeve (or asked not to be disturbed). */
  readonly #held = new Set<number>();
  #nextSeq = 0;
  /** Seqs of the strokes of undone paths (they keep their seq: the sleeve may have them). */
  readonly #undone: number[] = [];
  /** Segments kept as strokes (not dropped) in the paths still in the drawing. */
  #kept = 0;
  /** Of the kept strokes, those lasting longer than drawn (`lengthenedCount`). */
  #lengthened = 0;

  constructor(id: string, params: SimplifierParams) {
    this.id = id;
    this.params = params;
  }

  /** Starts a path; returns its index. */
  beginPath(kind: PointerKind): number {
    this.paths.push([]);
    this.frames.push([]);
    this.pointerKinds.push(kind);
    return this.paths.length - 1;
  }

  get currentPath(): number {
    return this.paths.length - 1;
  }

  addSample(sample: Sample): void {
    const path = this.paths[this.currentPath];
    if (path === undefined) throw new Error("addSample before beginPath");
    // Recordings need non-decreasing times; event clocks can tie or, rarely, step back.
    const previous = path[path.length - 1];
    path.push(previous && sample.t_ms < previous.t_ms ? { ...sample, t_ms: previous.t_ms } : sample);
  }

  addFrame(frame: Sample): void {
    const frames = this.frames[this.currentPath];
    if (frames === undefined) throw new Error("addFrame before beginPath");
    frames.push(frame);
  }

  /** Records a finished segment; a kept one becomes the next stroke (seq, drawing id). */
  addSegment(segment: Segment, intensity: number): DrawnSegment {
    let stroke: Stroke | null = null;
    if (segment.dropped === null) {
      stroke = {
        start: segment.start,
        end: segment.end,
        duration_ms: segment.duration_ms,
        intensity,
        drawing: this.id,
        seq: this.#nextSeq++,
      };
    }
    const drawn: DrawnSegment = { index: this.segments.length, path: this.currentPath, segment, stroke };
    this.segments.push(drawn);
    if (stroke?.seq != null) this.#bySeq.set(stroke.seq, drawn);
    if (stroke !== null) this.#kept++;
    if (lengthened(drawn)) this.#lengthened++;
    return drawn;
  }

  /** The segment sent as stroke `seq`, if this drawing sent it. */
  bySeq(seq: number): DrawnSegment | undefined {
    return this.#bySeq.get(seq);
  }

  /** The broker has acknowledged stroke `seq` (QoS 1 PUBACK): it is sent. */
  markAcked(seq: number): DrawnSegment | undefined {
    this.#acked.add(seq);
    return this.#bySeq.get(seq);
  }

  isAcked(drawn: DrawnSegment): boolean {
    return drawn.stroke?.seq != null && this.#acked.has(drawn.stroke.seq);
  }

  /**
   * Stroke `seq` was not felt (`why`: the sleeve refused it, Stop cancelled it, or it was never
   * sent): so it is drawn, however the broker acknowledged it.
   */
  markRefused(seq: number, why: Unfelt = "refused"): DrawnSegment | undefined {
    const drawn = this.#bySeq.get(seq);
    if (drawn !== undefined) this.#refused.set(seq, why);
    return drawn;
  }

  /** Stroke `seq` is held on the page, not sent: the wearer paused the sleeve. */
  markHeld(seq: number): DrawnSegment | undefined {
    const drawn = this.#bySeq.get(seq);
    if (drawn !== undefined) this.#held.add(seq);
    return drawn;
  }

  /** Stroke `seq` is no longer held (sent after all, or dropped). */
  unhold(seq: number): DrawnSegment | undefined {
    this.#held.delete(seq);
    return this.#bySeq.get(seq);
  }

  isHeld(drawn: DrawnSegment): boolean {
    return drawn.stroke?.seq != null && this.#held.has(drawn.stroke.seq);
  }

  isRefused(drawn: DrawnSegment): boolean {
    return drawn.stroke?.seq != null && this.#refused.has(drawn.stroke.seq);
  }

  /**
   * Whether stroke `seq` never left this page, and how: dropped before it was sent (counted as
   * never sent), or held (the wearer paused) when its path was taken back; null: it was sent (or
   * is still to be). Kept for the strokes of undone paths too.
   */
  unsent(seq: number): "dropped" | "held" | null {
    if (this.#refused.get(seq) === "unsent") return "dropped";
    return this.#held.has(seq) ? "held" : null;
  }

  /** The seqs of the strokes of paths taken back with Undo, in order: numbered, no longer drawn. */
  get undoneSeqs(): readonly number[] {
    return this.#undone;
  }

  /** Why stroke `drawn` was not felt; null when it was (or may yet be). */
  unfelt(drawn: DrawnSegment): Unfelt | null {
    return drawn.stroke?.seq == null ? null : (this.#refused.get(drawn.stroke.seq) ?? null);
  }

  /** Strokes numbered so far (sent, or queued to be), including those of undone paths. */
  get strokeCount(): number {
    return this.#nextSeq;
  }

  /**
   * Of the strokes, those sent lasting longer than they took to draw: drawn briefer than the
   * sleeve's floor where they could not merge, they last the floor (window.ts `Merger`).
   */
  get lengthenedCount(): number {
    return this.#lengthened;
  }

  /** How many `strokes` there are, without building the list. */
  get keptStrokeCount(): number {
    return this.#kept;
  }

  /** The strokes of the paths still in the drawing, in order. */
  get strokes(): Stroke[] {
    return this.segments.flatMap((drawn) => (drawn.stroke === null ? [] : [drawn.stroke]));
  }

  /**
   * Forgets the last path (Undo): its samples, frames and segments. Its strokes
   * keep their seq (the sleeve has them already); the next path continues after.
   */
  removeLastPath(): boolean {
    const path = this.currentPath;
    if (path < 0) return false;
    this.paths.pop();
    this.frames.pop();
    this.pointerKinds.pop();
    while (this.segments.length > 0 && this.segments[this.segments.length - 1]!.path === path) {
      const drawn = this.segments.pop()!;
      if (drawn.stroke?.seq != null) {
        this.#bySeq.delete(drawn.stroke.seq);
        this.#undone.push(drawn.stroke.seq);
      }
      if (drawn.stroke !== null) this.#kept--;
      if (lengthened(drawn)) this.#lengthened--;
    }
    return true;
  }

  /**
   * The same paths and segments under another id, strokes numbered from 0 again:
   * what Play again sends (the sleeve would refuse the old id's seqs as duplicates).
   */
  copyAs(id: string, params: SimplifierParams = this.params): Drawing {
    const copy = new Drawing(id, params);
    this.paths.forEach((samples, path) => {
      copy.beginPath(this.pointerKinds[path] ?? "mouse");
      copy.paths[path]!.push(...samples);
      copy.frames[path]!.push(...(this.frames[path] ?? []));
      for (const drawn of this.segments) {
        if (drawn.path === path) copy.addSegment(drawn.segment, drawn.stroke?.intensity ?? 1);
      }
    });
    return copy;
  }

  /**
   * The mean pressure of the current path's frames from `startMs` to `endMs`:
   * what "pen pressure sets intensity" uses. Walks back from the newest frame,
   * so the cost is the segment's own length, not the path's.
   */
  meanPressure(startMs: number, endMs: number): number {
    const frames = this.frames[this.currentPath] ?? [];
    let sum = 0;
    let count = 0;
    for (let i = frames.length - 1; i >= 0; i--) {
      const frame = frames[i]!;
      if (frame.t_ms < startMs) break;
      if (frame.t_ms <= endMs) {
        sum += frame.pressure;
        count++;
      }
    }
    return count > 0 ? sum / count : 0.5;
  }
}
