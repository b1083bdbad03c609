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
 * the cut are taken again into the next stroke. A stroke long enough to send lasts at most
 * {@code max_stroke_ms} of drawing (the latency cap) and holds at most {@code max_window}
 * samples (the work cap). The stroke after one the latency cap ended, if the cap or the release
 * ends it too, ends on the line of the stroke before when the bound allows and that end stays
 * on the grid, so a straight line cut by the cap stays straight. Too short or too brief strokes
 * are dropped with their reason. The float operations follow the reference's order, so every
 * value is the same to the last bit.
 */
public final class WindowSimplifier implements Simplifier {
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

  private final Params params;
  private final double maxError;
  private final int maxWindow;
  private final double maxStrokeMs;
  private final double minLength;
  private final double minDurationMs;
  private final double maxErrorSq;
  private final double minLengthSq;
  private final double reachLimit;
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

  public WindowSimplifier(Params params) {
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
    this.reachLimit = maxError - ROUNDING_SLACK;
    this.mapping = params.mapping();
    this.xExtent = params.columns() - 1;
    this.yExtent = params.rows() - 1;
  }

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
    place(x, y, sample.tMs(), sample);
    if (before == 0) {
      count = 1;
      reach = 0;
      emittedInPath = false;
      line = null;
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
        if (n >= maxWindow) {
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

  /** Whether every sample since the anchor lies within max_error of anchor -> (x, y); sets the
   * reach for (x, y) as the stroke's new last sample. A NaN is never farther than max_error. */
  private boolean keepsBound(int n, double x, double y) {
    if (n == 1) {
      reach = 0;
      return true;
    }
    double dx = x - xs[n - 1];
    double dy = y - ys[n - 1];
    double next = reach + Math.sqrt(dx * dx + dy * dy) + ROUNDING_SLACK;
    if (next <= reachLimit) {
      reach = next;
      return true;
    }
    double farthestSq = farthestSq(n, x, y, maxErrorSq);
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
