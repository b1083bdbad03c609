package feelmysign.simplify;

import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;

/**
 * The window simplifier: an error-bounded online simplifier over every drawn sample, cut at
 * features; a port of the reference {@code simplify/window.py} (and of its TypeScript port
 * {@code web/src/simplify/window.ts}, whose layout it follows) that reproduces
 * {@code testdata/window/}. The method and its sources are described there and in
 * docs/research.md.
 *
 * <p>It takes every pointer sample, not animation frames. A stroke grows one sample at a time
 * from its anchor; when a sample would put a sample since the anchor farther than
 * {@code max_error} (grid units) from the stroke, the stroke is cut at the sample farthest from
 * the chord (among those whose own stroke keeps the bound), emitted now, and the samples after
 * the cut are taken again into the next stroke; a cut that would end a piece briefer than the
 * sleeve's floor is made at the farthest of the samples drawn at least the floor after the
 * anchor, where the window holds one. A stroke long enough to send lasts at most
 * {@code max_stroke_ms} of drawing (the latency cap) and holds at most {@code max_window}
 * samples (the work cap). The stroke after one the latency cap ended, if the cap or the release
 * ends it too, ends on the line of the stroke before when the bound allows and that end stays
 * on the grid, so a straight line cut by the cap stays straight. Too short or too brief pieces
 * merge into the next ({@code Merger}); a path's last piece briefer than the sleeve's floor
 * merges at release into the stroke already sent before it where every drawn sample it has not
 * covered lies within {@code max_error} of that stroke (nothing more is sent; {@link
 * #mergedBack} counts them); only a tap is dropped with its reason. The float operations follow
 * the reference's order, so every value is the same to the last bit.
 *
 * <p>With {@code least_squares} the pieces come from the least-squares core instead ({@code
 * FitCore}, the reference's {@code simplify/fit.py}): strokes placed where the drawn samples lie
 * nearest them, each lasting the sleeve's floor where the bound allows, let go {@code
 * lookahead_ms} after their end or at the latency cap. Its pieces do not wait to merge (unless
 * {@code strict_minimums}): each is sent as it is, one briefer than the floor to last the floor.
 */
public final class WindowSimplifier implements Simplifier {
  private final PieceCore core;
  private final Merger merger;
  private final double restMs;
  /** The last sample pushed in the path being drawn (null between paths). */
  private Sample last;

  public WindowSimplifier(Params params) {
    this.restMs = params.number("rest_ms");
    boolean leastSquares = params.flag("least_squares");
    boolean strict = params.flag("strict_minimums");
    // The least squares' pieces are briefer than the floor only where no piece lasting it keeps
    // the bound: they do not wait to merge, unless strict (the reference's hold_short).
    this.core = leastSquares ? new FitCore(params) : new WindowCore(params);
    this.merger =
        new Merger(
            params.number("max_error"),
            params.number("min_length"),
            params.number("min_duration_ms"),
            params.number("floor_ms"),
            strict,
            !leastSquares || strict,
            params.number("max_stroke_ms"));
  }

  public Params params() {
    return core.params();
  }

  @Override
  public boolean drawing() {
    return core.drawing();
  }

  @Override
  public Sample lineStart() {
    return core.lineStart();
  }

  /**
   * One pointer sample while the pointer is down; the first of a path is the press.
   *
   * <p>A sample {@code rest_ms} or more after the one before (with the rest rule on) comes after a
   * stop: a pointer held still sends no event, and a source that does not sample it where it is
   * (the page does, every 32 ms; the Processing library at every frame) leaves a gap. The pen is
   * taken to have stood at the sample before until this one, as if sampled there at this one's
   * time: the rest rule sees the rest, and the stop is not played as a stroke as long as the
   * stop. The reference's {@code WindowSimplifier.push}.
   */
  @Override
  public List<Segment> push(Sample input) {
    Sample before = last;
    last = input;
    Sample still = before == null ? null : stillBefore(before, input, core.pointerMs(), restMs);
    if (still == null) {
      return pushOne(input);
    }
    List<Segment> first = pushOne(still);
    List<Segment> second = pushOne(input);
    if (first.isEmpty()) {
      return second;
    }
    if (second.isEmpty()) {
      return first;
    }
    List<Segment> both = new ArrayList<>(first);
    both.addAll(second);
    return both;
  }

  /**
   * The pen standing at {@code last} at {@code sample}'s time, where {@code sample} comes {@code
   * restMs} or more after the last time taken ({@code takenMs}: times never run backwards) with
   * the rest rule on; else null. The reference's {@code still_before}.
   */
  public static Sample stillBefore(Sample last, Sample sample, double takenMs, double restMs) {
    if (restMs > 0 && sample.tMs() - takenMs >= restMs) {
      return new Sample(sample.tMs(), last.x(), last.y(), last.pressure());
    }
    return null;
  }

  /**
   * The samples the simplifier takes for one path's {@code samples}: each, after the pen standing
   * at the one before where a stop left a gap ({@link #stillBefore}). What its strokes cover, for
   * tests and tools that check them against the samples. The reference's {@code taken_samples}.
   */
  public static List<Sample> takenSamples(List<Sample> samples, double restMs) {
    List<Sample> taken = new ArrayList<>(samples.size());
    double takenMs = Double.NEGATIVE_INFINITY;
    for (Sample sample : samples) {
      Sample still =
          taken.isEmpty() ? null : stillBefore(taken.get(taken.size() - 1), sample, takenMs, restMs);
      if (still != null) {
        taken.add(still);
      }
      taken.add(sample);
      takenMs = Math.max(takenMs, sample.tMs());
    }
    return taken;
  }

  private List<Segment> pushOne(Sample input) {
    List<Segment> pieces = core.push(input);
    double takenMs = core.lastMs();
    merger.sample(takenMs, core.lastX(), core.lastY());
    List<Segment> out = null;
    for (Segment piece : pieces) {
      out = merger.take(piece, takenMs, out);
    }
    if (core.rested()) {
      out = merger.rest(takenMs, out);
    }
    return out == null ? List.of() : out;
  }

  /** Pieces merged at release (or, with strict minimums, at a rest) into a stroke already sent,
   * over every path so far: nothing more was sent for them (each lies within max_error of the
   * stroke before it). */
  public int mergedBack() {
    return merger.mergedBack();
  }

  @Override
  public List<Segment> end() {
    last = null;
    double nowMs = core.pointerMs();
    List<Segment> out = null;
    for (Segment piece : core.end()) {
      out = merger.take(piece, nowMs, out);
    }
    out = merger.end(nowMs, out);
    return out == null ? List.of() : out;
  }
}

/**
 * What {@link WindowSimplifier} needs of its core ({@link WindowCore}, or {@link FitCore} with
 * {@code least_squares}): the pieces to merge, and each sample as the core took it, for the
 * merger.
 */
interface PieceCore extends Simplifier {
  Params params();

  /** Whether the last push found the pen resting (the stroke before the rest is final). */
  boolean rested();

  /** The time of the last sample taken, as taken (never before the one before). */
  double lastMs();

  /** The grid point of the last sample taken. */
  double lastX();

  double lastY();

  /** The time of the last sample pushed, as taken (0 before any). */
  double pointerMs();
}

/**
 * The window itself: strokes cut by the error bound, the bend rule and the caps, before
 * too-short pieces are merged ({@link WindowSimplifier} merges them).
 */
final class WindowCore implements PieceCore {
  /** The latency cap cuts at a feature drawn at least this share of max_stroke_ms after the
   * stroke's start, so that the stroke it ends is not too brief to be felt in its drawn time. */
  static final double CAP_FEATURE_SHARE = 0.5;
  /** A stroke whose samples all lie within this share of max_error of its chord is straight. */
  static final double STRAIGHT = 1e-6;
  /** A stroke the latency cap ends is a line when all its samples lie within this share of
   * max_error of it; the next may go on along it, its end moved at most this share. */
  static final double LINE_SHARE = 0.25;
  /** Far more than any rounding error of a distance computed here, far less than the least
   * max_error (0.001): what a stroke's reach adds for rounding, and the room kept below
   * max_error. */
  static final double ROUNDING_SLACK = 1e-9;
  /** A pen rests while its samples stay within this share of min_length of one point (never
   * farther than half of max_error, so the point that ends or starts a stroke covers the rest):
   * well below a stroke the sleeve renders, well above a still hand's jitter. */
  static final double REST_SHARE = 0.25;
  /** ... and never farther than a pen this slow (canvas pixels per ms) covers in rest_ms: a
   * quarter of a pixel a frame at 60 fps. A pen that stays near one point for all of rest_ms rests;
   * a slow, steady pen does not, as the distance it covers over the whole window tells: at twice
   * this speed (half a pixel a frame) or more, in any direction, it leaves the radius well within
   * rest_ms, even with its samples rounded to whole pixels. In pixels, not grid units: a hand's
   * speed on the screen does not depend on how the canvas maps onto the sleeve. */
  static final double REST_SPEED_PX_PER_MS = 0.015;

  private final Params params;
  private final double restMs;
  private final double restSq;
  private final double maxError;
  private final int maxWindow;
  private final double maxStrokeMs;
  private final double minLength;
  private final double minDurationMs;
  private final double maxErrorSq;
  private final double minLengthSq;
  /** The shortest piece the merger need not hold: the larger of floor_ms and min_duration_ms. */
  private final double floorMs;
  private final double reachLimit;
  private final double maxBend;
  private final double bendFloor;
  private final CanvasMapping mapping;
  /** The grid's extents: every stroke's start and end lies in [0, x] x [0, y]. */
  private final double xExtent;
  private final double yExtent;

  // The stroke being drawn as flat arrays (grid x, grid y, time) and their samples: [0, count)
  // is the stroke (its anchor first), [count, end) the samples to take next, in order. A cut
  // moves the samples after it down behind the new anchor, where they are taken again.
  private double[] xs = new double[64];
  private double[] ys = new double[64];
  private double[] ts = new double[64];
  private Sample[] samples = new Sample[64];
  private int count;
  private int end;
  /** Each sample's squared distance to a chord, while a cut looks for its feature. */
  private double[] distances = new double[64];
  /** The reach each sample of the stroke had when it was the last (index 0 never read). */
  private double[] reaches = new double[64];

  private Sample pointer;
  private boolean emittedInPath;
  /** The direction of the stroke the latency cap ended last, while the next may go on along it. */
  private double[] line;
  /** No sample since the anchor lies farther than this from anchor -> last sample. */
  private double reach;
  /** While the pen rests at the anchor: each sample near it moves the anchor's time. */
  private boolean resting;
  /** Whether the last push found the pen resting (the stroke before the rest is final). */
  private boolean rested;
  /** The last sample pushed, as taken: its time and grid point. */
  private double takenMs;
  private double takenX;
  private double takenY;

  WindowCore(Params params) {
    if (params.algorithm() != Algorithm.WINDOW) {
      throw new IllegalArgumentException("the window simplifier needs Params.window()");
    }
    this.params = params;
    this.maxError = params.number("max_error");
    this.maxWindow = params.integer("max_window");
    this.maxStrokeMs = params.number("max_stroke_ms");
    this.minLength = params.number("min_length");
    this.minDurationMs = params.number("min_duration_ms");
    this.maxErrorSq = maxError * maxError;
    this.minLengthSq = minLength * minLength;
    this.floorMs = Math.max(params.number("floor_ms"), minDurationMs);
    this.reachLimit = maxError - ROUNDING_SLACK;
    this.maxBend = params.number("max_bend");
    this.bendFloor = params.number("bend_floor");
    this.mapping = params.mapping();
    this.xExtent = params.columns() - 1;
    this.yExtent = params.rows() - 1;
    this.restMs = params.number("rest_ms");
    // The least of a share of min_length, half of max_error and what a pen at the rest speed
    // covers in rest_ms, at the canvas's tighter scale (as Python's and the page's rest radius).
    double rest = restRadius(minLength, maxError, restMs, mapping.scale());
    this.restSq = rest * rest;
  }

  /** How near one point a resting pen stays, in grid units: the least of a share of min_length,
   * half of max_error and what a pen at the rest speed covers in rest_ms, at the canvas's tighter
   * scale (as Python's and the page's rest radius). */
  static double restRadius(double minLength, double maxError, double restMs, double scale) {
    return Math.min(
        Math.min(REST_SHARE * minLength, 0.5 * maxError), REST_SPEED_PX_PER_MS * restMs * scale);
  }

  /** Whether the last push found the pen resting. */
  @Override
  public boolean rested() {
    return rested;
  }

  @Override
  public Params params() {
    return params;
  }

  @Override
  public boolean drawing() {
    return count > 0;
  }

  @Override
  public Sample lineStart() {
    return count > 0 ? samples[0] : null;
  }

  /** The time of the last sample taken, as taken (never before the one before). */
  @Override
  public double lastMs() {
    return takenMs;
  }

  @Override
  public double lastX() {
    return takenX;
  }

  @Override
  public double lastY() {
    return takenY;
  }

  /** The time of the last sample pushed, as taken (0 before any). */
  @Override
  public double pointerMs() {
    return pointer != null ? pointer.tMs() : 0.0;
  }

  private void place(double x, double y, double t, Sample sample) {
    if (end == xs.length) {
      int size = xs.length * 2;
      xs = Arrays.copyOf(xs, size);
      ys = Arrays.copyOf(ys, size);
      ts = Arrays.copyOf(ts, size);
      samples = Arrays.copyOf(samples, size);
      distances = Arrays.copyOf(distances, size);
      reaches = Arrays.copyOf(reaches, size);
    }
    xs[end] = x;
    ys[end] = y;
    ts[end] = t;
    samples[end] = sample;
    end++;
  }

  /** Only the anchor in the stroke: at (x, y), with the time and sample of the one at index;
   * the samples after index are taken again, in order, behind it. */
  private void restart(double x, double y, int index) {
    xs[0] = x;
    ys[0] = y;
    ts[0] = ts[index];
    samples[0] = samples[index];
    int to = 1;
    for (int from = index + 1; from < end; from++, to++) {
      xs[to] = xs[from];
      ys[to] = ys[from];
      ts[to] = ts[from];
      samples[to] = samples[from];
    }
    count = 1;
    end = end - index;
  }

  /** The anchor at another time (while the pen rests or crawls), its sample too. */
  private void retime(double t) {
    ts[0] = t;
    Sample anchor = samples[0];
    samples[0] = new Sample(t, anchor.x(), anchor.y(), anchor.pressure());
  }

  /** The sample to take next (at count) is not taken: the ones after it move down. */
  private void skip() {
    for (int to = count; to < end - 1; to++) {
      xs[to] = xs[to + 1];
      ys[to] = ys[to + 1];
      ts[to] = ts[to + 1];
      samples[to] = samples[to + 1];
    }
    end--;
  }

  @Override
  public List<Segment> push(Sample input) {
    // Times never run backwards (two event sources' clocks): an earlier sample takes the last.
    Sample sample =
        count > 0 && input.tMs() < ts[count - 1]
            ? new Sample(ts[count - 1], input.x(), input.y(), input.pressure())
            : input;
    pointer = sample;
    double x = mapping.gridX(sample.x());
    double y = mapping.gridY(sample.y());
    int before = count;
    takenMs = sample.tMs();
    takenX = x;
    takenY = y;
    rested = false;
    place(x, y, sample.tMs(), sample);
    if (before == 0) {
      count = 1;
      reach = 0;
      emittedInPath = false;
      line = null;
      resting = false;
      return List.of();
    }
    List<Segment> out = add();
    return out == null ? List.of() : out;
  }

  @Override
  public List<Segment> end() {
    int n = count;
    if (n == 0) {
      return List.of();
    }
    count = 0;
    end = 0;
    resting = false;
    // The last sample already ends a stroke (a cut at the work cap).
    if (n == 1 && emittedInPath) {
      return List.of();
    }
    double[] stop = continued(n - 1);
    return List.of(finish(xs[0], ys[0], ts[0], stop[0], stop[1], ts[n - 1]));
  }

  /** The samples to take join the stroke in order, each cutting it first where it must. */
  private List<Segment> add() {
    List<Segment> out = null;
    double capMs = maxStrokeMs;
    while (true) {
      int n = count;
      double x = xs[n];
      double y = ys[n];
      double t = ts[n];
      if (resting) {
        if (n == 1 && squared(x - xs[0], y - ys[0]) <= restSq) {
          // The pen still rests: the next stroke starts when it moves on, not before.
          retime(t);
          skip();
          if (count == end) {
            return out;
          }
          continue;
        }
        resting = false;
      }
      if (capMs > 0 && n > 1 && t - ts[0] > capMs && !sendable(xs[0], ys[0], xs[n - 1], ys[n - 1])) {
        // The pen crawls: too little drawn in max_stroke_ms to send. The stroke starts later
        // rather than lasting longer, so the cap holds for it too.
        retime(t - capMs);
      }
      if (capMs > 0 && n > 1 && t - ts[0] > capMs && sendable(xs[0], ys[0], xs[n - 1], ys[n - 1])) {
        int cut = capCut(n);
        double[] vertex = continued(cut);
        if (out == null) {
          out = new ArrayList<>(2);
        }
        out.add(finish(xs[0], ys[0], ts[0], vertex[0], vertex[1], ts[cut]));
        line = lineOf(cut, vertex);
        // The samples after the cut, this one included, are taken again into the next stroke.
        restart(vertex[0], vertex[1], cut);
        reach = 0;
        continue;
      }
      if (!keepsBound(n, x, y)) {
        int cut = feature(n, x, y, 1);
        double floorEndMs = ts[0] + floorMs;
        if (ts[cut] < floorEndMs && floorEndMs <= ts[n - 1]) {
          // The piece would be briefer than the sleeve's floor, and the window holds a longer
          // one: cut at the feature among the samples drawn at least the floor after the anchor
          // (the last one always keeps the bound), so the sleeve need not slow the piece and the
          // merger need not hold it.
          int later = cut + 1;
          while (ts[later] < floorEndMs) {
            later++;
          }
          cut = feature(n, x, y, later);
        }
        double endX = xs[cut];
        double endY = ys[cut];
        if (out == null) {
          out = new ArrayList<>(2);
        }
        out.add(finish(xs[0], ys[0], ts[0], endX, endY, ts[cut]));
        line = null;
        restart(endX, endY, cut);
        reach = 0;
      } else {
        count = n + 1;
        reaches[n] = reach;
        if (rests(n + 1)) {
          // The pen rests: the stroke before it, if any, is out; the anchor waits for the pen.
          if (restStroke != null) {
            if (out == null) {
              out = new ArrayList<>(2);
            }
            out.add(restStroke);
            restStroke = null;
          }
        } else if (n >= maxWindow) {
          if (out == null) {
            out = new ArrayList<>(2);
          }
          out.add(finish(xs[0], ys[0], ts[0], x, y, t));
          line = null;
          restart(x, y, n);
          reach = 0;
        }
      }
      if (count == end) {
        return out;
      }
    }
  }

  /** The stroke a rest ended, between rests() and add() (null if all was rest). */
  private Segment restStroke;

  /**
   * Whether the pen has rested rest_ms at the stroke's newest sample, index n - 1: its samples of
   * the last rest_ms or more all lie within the rest radius of it. The stroke drawn up to the
   * rest then ends there at the time the rest began, and is sent now (restStroke); the rest is
   * not played (the next stroke starts where and when the pen moves on). If the stroke is all
   * rest, its anchor waits instead.
   */
  private boolean rests(int n) {
    int last = n - 1;
    double t = ts[last];
    if (restMs <= 0 || t - ts[0] < restMs) {
      return false;
    }
    double x = xs[last];
    double y = ys[last];
    int start = last;
    while (start > 0 && squared(xs[start - 1] - x, ys[start - 1] - y) <= restSq) {
      start--;
    }
    if (t - ts[start] < restMs) {
      return false;
    }
    if (start == 0) {
      Sample anchor = samples[0];
      restart(xs[0], ys[0], last);
      samples[0] = anchor;
      retime(t);
    } else {
      restStroke = finish(xs[0], ys[0], ts[0], x, y, ts[start]);
      restart(x, y, last);
    }
    line = null;
    reach = 0;
    resting = true;
    rested = true;
    return true;
  }

  private static double squared(double dx, double dy) {
    return dx * dx + dy * dy;
  }

  /** Whether every sample since the anchor lies within max_error of anchor -> (x, y); sets the
   * reach for (x, y) as the stroke's new last sample. A NaN is never farther than max_error. */
  private boolean keepsBound(int n, double x, double y) {
    if (n == 1) {
      reach = 0;
      return true;
    }
    double limitReach = reachLimit;
    double limitSq = maxErrorSq;
    if (maxBend > 0.0) {
      // The bend rule: a round shape is cut before its chord strays farther than a share of the
      // chord's length, never under the floor, never over max_error.
      double cx = x - xs[0];
      double cy = y - ys[0];
      double limit = Math.max(maxBend * Math.sqrt(cx * cx + cy * cy), bendFloor);
      if (limit < maxError) {
        limitReach = limit - ROUNDING_SLACK;
        limitSq = limit * limit;
      }
    }
    double dx = x - xs[n - 1];
    double dy = y - ys[n - 1];
    double next = reach + Math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK;
    if (next <= limitReach) {
      reach = next;
      return true;
    }
    double farthestSq = farthestSq(n, x, y, limitSq);
    if (farthestSq < 0) {
      return false;
    }
    reach = Math.sqrt(farthestSq) + ROUNDING_SLACK;
    return true;
  }

  /** Whether window[1..index] surely lie within limit + slack of anchor -> (endX, endY). */
  private boolean reachesNear(int index, double endX, double endY, double limit) {
    if (index == 0) {
      return false;
    }
    double dx = endX - xs[index];
    double dy = endY - ys[index];
    return reaches[index] + Math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK <= limit;
  }

  /** Where the latency cap cuts: at a feature in the stroke's later part, else at its end. */
  private int capCut(int n) {
    int last = n - 1;
    double earliest = ts[0] + CAP_FEATURE_SHARE * maxStrokeMs;
    int first = 1;
    while (first < last && ts[first] < earliest) {
      first++;
    }
    int cut = feature(n, xs[last], ys[last], first);
    double straight = STRAIGHT * maxError;
    double farSq = distanceSq(xs[cut], ys[cut], xs[0], ys[0], xs[last], ys[last]);
    boolean bends = farSq > straight * straight;
    return bends && sendable(xs[0], ys[0], xs[cut], ys[cut]) ? cut : last;
  }

  /** Where a stroke that the latency cap or the release ends, ending at window[cut], ends. */
  private double[] continued(int cut) {
    double atX = xs[cut];
    double atY = ys[cut];
    if (line == null) {
      return new double[] {atX, atY};
    }
    double ux = line[0];
    double uy = line[1];
    double ax = xs[0];
    double ay = ys[0];
    double along = (atX - ax) * ux + (atY - ay) * uy;
    if (along <= 0) {
      return new double[] {atX, atY};
    }
    double endX = ax + along * ux;
    double endY = ay + along * uy;
    // On the line but off the grid: the sleeve refuses a stroke that ends off it, so keep the
    // drawn sample, which the mapping put on it (not the projection clamped: that would bend).
    if (!(0.0 <= endX && endX <= xExtent && 0.0 <= endY && endY <= yExtent)) {
      return new double[] {atX, atY};
    }
    double limit = LINE_SHARE * maxError;
    if (distanceSq(atX, atY, endX, endY, endX, endY) > limit * limit) {
      return new double[] {atX, atY}; // a bend, not noise
    }
    if (!sendable(ax, ay, endX, endY)) {
      return new double[] {atX, atY};
    }
    if (!reachesNear(cut, endX, endY, reachLimit) && !within(cut + 1, endX, endY, maxErrorSq)) {
      return new double[] {atX, atY};
    }
    return new double[] {endX, endY};
  }

  /** The direction of window[0] -> end if it is a line (every sample up to window[cut] within
   * LINE_SHARE x max_error of it), else null. */
  private double[] lineOf(int cut, double[] stop) {
    double limit = LINE_SHARE * maxError;
    boolean certain = reachesNear(cut, stop[0], stop[1], limit - ROUNDING_SLACK);
    if (!certain && !within(cut + 1, stop[0], stop[1], limit * limit)) {
      return null;
    }
    double dx = stop[0] - xs[0];
    double dy = stop[1] - ys[0];
    double length = Math.sqrt(dx * dx + dy * dy);
    return length > 0.0 ? new double[] {dx / length, dy / length} : null;
  }

  /** Whether start -> end is long enough to send (the cap never cuts off a dropped stroke). */
  private boolean sendable(double startX, double startY, double endX, double endY) {
    double dx = endX - startX;
    double dy = endY - startY;
    return dx * dx + dy * dy >= minLengthSq;
  }

  /**
   * Where to cut: the sample farthest from anchor -> end whose own stroke keeps the bound (the
   * last sample always does). Ties go to the later sample, as the reference's sort by
   * (distance, index) descending.
   */
  private int feature(int n, double endX, double endY, int first) {
    double ax = xs[0];
    double ay = ys[0];
    boolean finite = true;
    int farthest = -1;
    double farthestDistance = -1;
    double dx = endX - ax;
    double dy = endY - ay;
    double lengthSq = dx * dx + dy * dy;
    for (int i = first; i < n; i++) {
      double d = offsetSq(xs[i] - ax, ys[i] - ay, dx, dy, lengthSq);
      distances[i] = d;
      if (Double.isNaN(d)) {
        finite = false;
      } else if (d >= farthestDistance) {
        farthestDistance = d;
        farthest = i;
      }
    }
    if (!finite) {
      return featureSorted(n, first);
    }
    if (farthest < 0) {
      return n - 1; // unreachable: the last sample fits by construction
    }
    if (reaches[farthest] <= reachLimit || within(farthest, xs[farthest], ys[farthest], maxErrorSq)) {
      return farthest;
    }
    distances[farthest] = -1;
    // Farthest first and, at equal distances, the later sample first; -1 marks a sample tried.
    while (true) {
      int best = -1;
      double bestDistance = -1;
      for (int i = n - 1; i >= first; i--) {
        if (distances[i] > bestDistance) {
          bestDistance = distances[i];
          best = i;
        }
      }
      if (best < 0) {
        return n - 1; // unreachable: the last sample fits by construction
      }
      if (reaches[best] <= reachLimit || within(best, xs[best], ys[best], maxErrorSq)) {
        return best;
      }
      distances[best] = -1;
    }
  }

  /** {@link #feature} for distances that are not all numbers (a NaN drawn): a sort. */
  private int featureSorted(int n, int first) {
    List<Integer> ranked = new ArrayList<>();
    for (int i = first; i < n; i++) {
      ranked.add(i);
    }
    ranked.sort(
        (a, b) -> {
          double diff = distances[b] - distances[a];
          if (diff != 0 && !Double.isNaN(diff)) {
            return diff > 0 ? 1 : -1;
          }
          return Integer.compare(b, a);
        });
    for (int index : ranked) {
      if (reaches[index] <= reachLimit || within(index, xs[index], ys[index], maxErrorSq)) {
        return index;
      }
    }
    return n - 1;
  }

  private boolean within(int stop, double endX, double endY, double limitSq) {
    return farthestSq(stop, endX, endY, limitSq) >= 0;
  }

  /**
   * The greatest squared distance of window[1..stop) to window[0] -> (endX, endY) (0 if none,
   * NaN counting as none), or -1 as soon as one exceeds limitSq (see {@link #offsetSq}).
   */
  private double farthestSq(int stop, double endX, double endY, double limitSq) {
    double ax = xs[0];
    double ay = ys[0];
    double dx = endX - ax;
    double dy = endY - ay;
    double lengthSq = dx * dx + dy * dy;
    double farthest = 0;
    for (int i = 1; i < stop; i++) {
      double d = offsetSq(xs[i] - ax, ys[i] - ay, dx, dy, lengthSq);
      if (d > limitSq) {
        return -1;
      }
      if (d > farthest) {
        farthest = d;
      }
    }
    return farthest;
  }

  private Segment finish(
      double startX, double startY, double startMs, double endX, double endY, double endMs) {
    emittedInPath = true;
    double emittedAtMs = pointer != null ? pointer.tMs() : endMs;
    return new Segment(startX, startY, endX, endY, startMs, endMs, emittedAtMs, null)
        .checked(minLength, minDurationMs);
  }

  /**
   * Squared distance of q (a sample less the anchor) to the segment anchor -> anchor + d, whose
   * squared length is lengthSq: {@link #distanceSq} with its float operations in its order, so
   * every distance is the same to the last bit (t = 1 and t = 0 need no multiplication).
   */
  private static double offsetSq(double qx, double qy, double dx, double dy, double lengthSq) {
    if (lengthSq > 0) {
      double t = (qx * dx + qy * dy) / lengthSq;
      if (t >= 1) {
        qx = qx - dx;
        qy = qy - dy;
      } else if (!(t <= 0)) {
        qx = qx - t * dx;
        qy = qy - t * dy;
      }
    }
    return qx * qx + qy * qy;
  }

  /** Squared distance from (px, py) to the segment (ax, ay) -> (ex, ey) (its nearest point). */
  static double distanceSq(double px, double py, double ax, double ay, double ex, double ey) {
    double dx = ex - ax;
    double dy = ey - ay;
    double qx = px - ax;
    double qy = py - ay;
    double lengthSq = dx * dx + dy * dy;
    if (lengthSq > 0.0) {
      // The nearest point of the segment: the projection, clamped onto it (as Python's max and
      // min compare: a NaN stays NaN).
      double t = (qx * dx + qy * dy) / lengthSq;
      if (t < 0.0) {
        t = 0.0;
      }
      if (1.0 < t) {
        t = 1.0;
      }
      qx = qx - t * dx;
      qy = qy - t * dy;
    }
    return qx * qx + qy * qy;
  }
}

/**
 * Merges the pieces the window cuts too short to send into a neighbour, never dropping one (the
 * reference's {@code Merger}). A piece is too short when it is shorter than min_length or
 * briefer than the larger of min_duration_ms and floor_ms (the sleeve would slow it). A short
 * piece waits for the next; the two become one stroke when every drawn sample of both lies
 * within max_error of it (still short, it waits again), else the short one is sent as it is. A
 * piece long enough is sent at once (holding each back would delay the drawing), so a path's
 * last piece, if short, is sent short, unless at release it is briefer than the floor and lies,
 * with every drawn sample not yet covered, within max_error of the stroke already sent before
 * it: then it merges into that stroke and nothing more is sent. Only a path's one and only
 * piece, too short, is dropped with its reason. With strict minimums (a wearer's), a piece below
 * them merges into the next whatever the bound, but never across a rest ({@link #rest}), and one
 * left at release or at a rest merges back where the bound allows, else is dropped with its
 * reason.
 */
final class Merger {
  private final double maxError;
  private final double minLength;
  private final double minDurationMs;
  private final double shortMs;
  private final boolean strict;
  /** Whether a piece too short or too brief waits to merge (the window's pieces). The least
   * squares' pieces do not, unless strict: each is sent as it is, a brief one to last the
   * floor. */
  private final boolean holdShort;
  // With holdShort off (the least squares' pieces): no merge makes a stroke outlast this (the
  // latency cap, ms; 0: no limit). The window's own merges keep it by their pieces.
  private final double capMs;
  // The drawn samples not yet covered by a sent stroke (grid units, ms), oldest first:
  // [first, size).
  private double[] xs = new double[64];
  private double[] ys = new double[64];
  private double[] ts = new double[64];
  private int first;
  private int size;
  private Segment held;
  private boolean sentInPath;
  // The path's last sent stroke (null before its first): a piece briefer than the sleeve's floor
  // left at release merges into it when every drawn sample it has not covered lies within
  // max_error of it (end).
  private Segment last;
  // Pieces merged at release (or, strict, at a rest) into a stroke already sent (nothing more is
  // sent for them), in all.
  private int mergedBack;

  Merger(
      double maxError,
      double minLength,
      double minDurationMs,
      double floorMs,
      boolean strict,
      boolean holdShort,
      double capMs) {
    this.maxError = maxError;
    this.minLength = minLength;
    this.minDurationMs = minDurationMs;
    this.shortMs = Math.max(minDurationMs, floorMs);
    this.strict = strict;
    this.holdShort = holdShort;
    this.capMs = capMs;
  }

  Merger(double maxError, double minLength, double minDurationMs, double floorMs, boolean strict) {
    this(maxError, minLength, minDurationMs, floorMs, strict, true, 0.0);
  }

  Merger(double maxError, double minLength, double minDurationMs, double floorMs) {
    this(maxError, minLength, minDurationMs, floorMs, false);
  }

  /** A drawn sample, in order (its time as the window took it). */
  void sample(double tMs, double x, double y) {
    if (size == xs.length) {
      int live = size - first;
      int capacity = live * 2 < xs.length ? xs.length : xs.length * 2;
      double[] nx = new double[capacity];
      double[] ny = new double[capacity];
      double[] nt = new double[capacity];
      System.arraycopy(xs, first, nx, 0, live);
      System.arraycopy(ys, first, ny, 0, live);
      System.arraycopy(ts, first, nt, 0, live);
      xs = nx;
      ys = ny;
      ts = nt;
      first = 0;
      size = live;
    }
    xs[size] = x;
    ys[size] = y;
    ts[size] = tMs;
    size++;
  }

  private boolean isShort(Segment segment) {
    // A path's first piece waits even where the least squares send pieces as they are:
    // a tap is dropped.
    return (holdShort || !sentInPath) && (segment.length() < minLength || segment.drawnMs() < shortMs);
  }

  private boolean belowMinimums(Segment segment) {
    return segment.length() < minLength || segment.drawnMs() < minDurationMs;
  }

  /** Whether every sample not yet covered, drawn up to the second's end, lies within max_error
   * of the first's start -> the second's end. All of them, not only those after the first's
   * start: a stroke whose pen crawled or rested starts after samples it covers. */
  private boolean fits(Segment from, Segment to) {
    return fits(from.startX(), from.startY(), to.endX(), to.endY(), to.endMs());
  }

  /** Whether every sample not yet covered, drawn up to endMs, lies within max_error of the
   * segment (startX, startY) -> (endX, endY). */
  private boolean fits(double startX, double startY, double endX, double endY, double endMs) {
    double limitSq = maxError * maxError;
    for (int i = first; i < size; i++) {
      double t = ts[i];
      if (t > endMs) {
        break;
      }
      if (WindowCore.distanceSq(xs[i], ys[i], startX, startY, endX, endY) > limitSq) {
        return false;
      }
    }
    return true;
  }

  /** Pieces merged at release (or, strict, at a rest) into a stroke already sent ({@link #end},
   * {@link #rest}), over every path so far. */
  int mergedBack() {
    return mergedBack;
  }

  private static List<Segment> add(List<Segment> out, Segment segment) {
    List<Segment> list = out == null ? new ArrayList<>(2) : out;
    list.add(segment);
    return list;
  }

  private List<Segment> send(Segment segment, double nowMs, List<Segment> out) {
    sentInPath = true;
    last = segment;
    // The samples before its end are covered now (those at its end may start the next).
    while (first < size && ts[first] < segment.endMs()) {
      first++;
    }
    // A stroke drawn briefer than the sleeve's floor (one that could not merge) lasts the floor:
    // the sleeve would slow it to that, and has nothing to adjust (its times stay the drawn ones).
    double playMs = segment.endMs() - segment.startMs() < shortMs ? shortMs : Double.NaN;
    return add(
        out,
        new Segment(
            segment.startX(),
            segment.startY(),
            segment.endX(),
            segment.endY(),
            segment.startMs(),
            segment.endMs(),
            nowMs,
            null,
            segment.merged(),
            playMs));
  }

  /** A piece the window cut: the strokes sent now, added to out (none while a short one
   * waits). */
  List<Segment> take(Segment input, double nowMs, List<Segment> out) {
    Segment piece = input;
    List<Segment> result = out;
    Segment before = held;
    if (before != null) {
      held = null;
      boolean withinCap = holdShort || capMs <= 0.0 || piece.endMs() - before.startMs() <= capMs;
      if ((withinCap && fits(before, piece)) || (strict && belowMinimums(before))) {
        piece =
            new Segment(
                before.startX(),
                before.startY(),
                piece.endX(),
                piece.endY(),
                before.startMs(),
                piece.endMs(),
                nowMs,
                null,
                before.merged() + piece.merged() + 1);
      } else {
        result = send(before, nowMs, result);
      }
    }
    if (isShort(piece)) {
      held = piece;
      return result;
    }
    return send(piece, nowMs, result);
  }

  /** The earliest end a piece starting at startMs lasts floorMs to: startMs + floorMs, or the
   * double above it where that sum rounds down (15000.1 + 73.701 - 15000.1 is 73.70099999999911,
   * which the sleeve would slow to 73.701 and report adjusted). Python floor_end_ms. */
  static double floorEndMs(double startMs, double floorMs) {
    double endMs = startMs + floorMs;
    while (endMs - startMs < floorMs) {
      endMs = Math.nextUp(endMs);
    }
    return endMs;
  }

  /** The pen rests (since the held piece's end, until nowMs): the held piece is let go now
   * rather than merged with what comes after the rest, which would play the rest. If it is
   * briefer than the sleeve's floor, it takes the time it needs from the rest: the pen was at its
   * end then, and it is sent. With strict minimums, a piece still below them is not sent: as at
   * release, it merges into the path's last sent stroke where that keeps the bound
   * ({@link #mergesBack}), else it is dropped with its reason. */
  List<Segment> rest(double nowMs, List<Segment> out) {
    Segment piece = held;
    if (piece == null) {
      return out;
    }
    if (piece.drawnMs() < shortMs && nowMs > piece.endMs()) {
      piece =
          new Segment(
              piece.startX(),
              piece.startY(),
              piece.endX(),
              piece.endY(),
              piece.startMs(),
              Math.min(floorEndMs(piece.startMs(), shortMs), nowMs),
              piece.emittedAtMs(),
              piece.dropped(),
              piece.merged());
    }
    held = null;
    if (strict && belowMinimums(piece)) {
      List<Segment> result = out;
      if (mergesBack(piece)) {
        mergedBack += piece.merged() + 1;
      } else {
        result = add(result, dropped(piece, nowMs, reason(piece)));
      }
      // Its samples are let go with it (those at its end may start the next).
      while (first < size && ts[first] < piece.endMs()) {
        first++;
      }
      return result;
    }
    return send(piece, nowMs, out);
  }

  /** Why segment is too short to send (null if it is not). */
  private String reason(Segment segment) {
    if (segment.length() < minLength) {
      return Segment.NOT_ENOUGH_DISTANCE;
    }
    if (segment.drawnMs() < minDurationMs) {
      return Segment.NOT_ENOUGH_DURATION;
    }
    return null;
  }

  /** segment, dropped for reason at nowMs. */
  private static Segment dropped(Segment segment, double nowMs, String reason) {
    return new Segment(
        segment.startX(),
        segment.startY(),
        segment.endX(),
        segment.endY(),
        segment.startMs(),
        segment.endMs(),
        nowMs,
        reason,
        segment.merged());
  }

  /** Whether the piece held at release merges into the path's last sent stroke: it is briefer
   * than the sleeve's floor (or, with strict minimums, shorter than min_length: it would be
   * dropped), and every drawn sample not yet covered lies within max_error of that stroke. */
  private boolean mergesBack(Segment piece) {
    if (last == null) {
      return false;
    }
    if (!(piece.drawnMs() < shortMs || (strict && piece.length() < minLength))) {
      return false;
    }
    return fits(last.startX(), last.startY(), last.endX(), last.endY(), Double.POSITIVE_INFINITY);
  }

  /** Release, after the window's last piece: the held piece merges into the path's last sent
   * stroke where that keeps the bound ({@link #mergesBack}: nothing more is sent), else it is
   * sent (or, a path's only piece too short, dropped with its reason). */
  List<Segment> end(double nowMs, List<Segment> out) {
    List<Segment> result = out;
    if (held != null && mergesBack(held)) {
      mergedBack += held.merged() + 1;
      held = null;
    }
    if (held != null) {
      String reason = !sentInPath || strict ? reason(held) : null;
      result = reason != null ? add(result, dropped(held, nowMs, reason)) : send(held, nowMs, result);
    }
    held = null;
    sentInPath = false;
    last = null;
    first = 0;
    size = 0;
    return result;
  }
}
