package feelmysign.simplify;

import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;

/**
 * The window simplifier's least-squares core ({@code least_squares}): a port of the reference
 * {@code simplify/fit.py} ({@code FitCore}) that reproduces {@code testdata/window/}'s
 * least-squares vectors. The method and its sources are described there and in docs/research.md.
 *
 * <p>At each sample it keeps, over the samples since the last stroke it let go (the anchor), the
 * polyline through drawn samples with the least integral square error among those whose strokes
 * all keep every sample within {@code max_error} of the segment and last at least the sleeve's
 * floor ({@code floor_ms}, or {@code min_duration_ms} if longer); where no stroke lasting the
 * floor keeps the bound, the fewest briefer ones. Each sample's best polyline is found once, from
 * those of the samples before it (Perez and Vidal's dynamic program), each piece's error from
 * running sums in O(1).
 *
 * <p>A stroke is let go, its first vertex after the anchor final, once the pen has drawn {@code
 * lookahead_ms} past that vertex, or once it lasts more than {@code max_stroke_ms}; with no vertex
 * yet and the stroke from the anchor longer than the cap, the stroke to the sample before is let
 * go as one. At release the polyline to the last sample is let go whole. Kept from the window
 * ({@link WindowCore}): the mapping, times that never run backwards, the rest rule and the work
 * cap ({@code max_window} samples per piece after its start).
 *
 * <p>Every float operation is the reference's, in its order (left to right, no fused
 * multiply-add), and every tie is broken as it breaks it, so every stroke is the same to the last
 * bit.
 */
final class FitCore implements PieceCore {
  private final Params params;
  private final double maxErrorSq;
  /** The sleeve's floor: the larger of floor_ms and min_duration_ms. */
  private final double floorMs;
  private final double restSq;
  private final double restMs;
  private final double minLength;
  private final double minDurationMs;
  private final double maxStrokeMs;
  private final double lookaheadMs;
  private final int maxWindow;
  private final CanvasMapping mapping;

  // The samples since the anchor, the anchor first: [0, count) of grid points, times, samples.
  private double[] xs = new double[64];
  private double[] ys = new double[64];
  private double[] ts = new double[64];
  private Sample[] samples = new Sample[64];
  private int count;
  // Running sums of x, y, x^2, y^2 and xy over the samples, relative to the anchor's point:
  // index m holds the sum over samples [0, m - 1] (index 0 is 0), so [0, count] is in use.
  private double[] sumX = new double[65];
  private double[] sumY = new double[65];
  private double[] sumXx = new double[65];
  private double[] sumYy = new double[65];
  private double[] sumXy = new double[65];
  // Each sample's best polyline from the anchor (every piece at the floor, where the bound lets
  // it be): its squared error, its count of pieces briefer than the floor and its last vertex.
  private double[] best = new double[64];
  private int[] brief = new int[64];
  private int[] before = new int[64];
  // A piece's error per start (from the first start), for the sample errorsEnd (reused).
  private double[] errors = new double[64];
  private int errorsEnd = -1;
  // Per sample, the sample that last broke the bound of a piece from it (-1: none yet).
  private int[] broke = new int[64];
  // The starts of a choice after its first one broke the bound, and their counts and totals.
  private Integer[] starts = new Integer[0];
  private int[] startCounts = new int[64];
  private double[] startTotals = new double[64];

  private Sample pointer;
  private boolean emittedInPath;
  /** While the pen rests: the point it rests at; each sample near it retimes the anchor. */
  private boolean resting;
  private double restX;
  private double restY;
  /** Whether the last push found the pen resting (the polyline before the rest is out). */
  private boolean rested;
  /** The last sample pushed, as taken: its time and grid point. */
  private double takenMs;
  private double takenX;
  private double takenY;

  FitCore(Params params) {
    if (params.algorithm() != Algorithm.WINDOW) {
      throw new IllegalArgumentException("the window simplifier needs Params.window()");
    }
    this.params = params;
    double maxError = params.number("max_error");
    this.maxErrorSq = maxError * maxError;
    this.minLength = params.number("min_length");
    this.minDurationMs = params.number("min_duration_ms");
    this.floorMs = Math.max(params.number("floor_ms"), minDurationMs);
    this.restMs = params.number("rest_ms");
    this.mapping = params.mapping();
    double rest = WindowCore.restRadius(minLength, maxError, restMs, mapping.scale());
    this.restSq = rest * rest;
    this.maxStrokeMs = params.number("max_stroke_ms");
    this.lookaheadMs = params.number("lookahead_ms");
    this.maxWindow = params.integer("max_window");
  }

  @Override
  public Params params() {
    return params;
  }

  @Override
  public boolean rested() {
    return rested;
  }

  @Override
  public boolean drawing() {
    return count > 0;
  }

  @Override
  public Sample lineStart() {
    return count > 0 ? samples[0] : null;
  }

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

  @Override
  public double pointerMs() {
    return pointer != null ? pointer.tMs() : 0.0;
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
    double t = sample.tMs();
    takenMs = t;
    takenX = x;
    takenY = y;
    rested = false;
    if (count == 0) {
      emittedInPath = false;
      resting = false;
      put(0, x, y, t, sample);
      restart(0, 1);
      return List.of();
    }
    if (resting) {
      double dx = x - restX;
      double dy = y - restY;
      if (count == 1 && dx * dx + dy * dy <= restSq) {
        retime(t);
        return List.of();
      }
      resting = false;
    }
    List<Segment> out = new ArrayList<>(2);
    append(x, y, t, sample);
    if (rests(out)) {
      return out;
    }
    letGo(out);
    return out;
  }

  /** Release: the best polyline to the last sample, every stroke at the floor (a lone sample
   * gives one piece of length 0, unless a stroke of the path ends there already). */
  @Override
  public List<Segment> end() {
    int n = count;
    resting = false;
    if (n == 0) {
      return List.of();
    }
    List<Segment> out = new ArrayList<>(4);
    if (n == 1) {
      if (!emittedInPath) {
        out.add(piece(0, 0));
      }
    } else {
      polyline(n - 1, out);
    }
    count = 0;
    return out;
  }

  // --- the polyline ----------------------------------------------------------------------------

  /** Room for {@code size} samples (and their sums). */
  private void ensure(int size) {
    if (size <= xs.length) {
      return;
    }
    int capacity = Math.max(size, xs.length * 2);
    xs = Arrays.copyOf(xs, capacity);
    ys = Arrays.copyOf(ys, capacity);
    ts = Arrays.copyOf(ts, capacity);
    samples = Arrays.copyOf(samples, capacity);
    sumX = Arrays.copyOf(sumX, capacity + 1);
    sumY = Arrays.copyOf(sumY, capacity + 1);
    sumXx = Arrays.copyOf(sumXx, capacity + 1);
    sumYy = Arrays.copyOf(sumYy, capacity + 1);
    sumXy = Arrays.copyOf(sumXy, capacity + 1);
    best = Arrays.copyOf(best, capacity);
    brief = Arrays.copyOf(brief, capacity);
    before = Arrays.copyOf(before, capacity);
    errors = Arrays.copyOf(errors, capacity);
    broke = Arrays.copyOf(broke, capacity);
    startCounts = Arrays.copyOf(startCounts, capacity);
    startTotals = Arrays.copyOf(startTotals, capacity);
  }

  private void put(int index, double x, double y, double t, Sample sample) {
    ensure(index + 1);
    xs[index] = x;
    ys[index] = y;
    ts[index] = t;
    samples[index] = sample;
  }

  /**
   * The samples [from, from + n) since a new anchor (the one at from): moved down to [0, n), then
   * their running sums and best polylines again (the reference's {@code _restart_at}).
   */
  private void restart(int from, int n) {
    if (from > 0) {
      System.arraycopy(xs, from, xs, 0, n);
      System.arraycopy(ys, from, ys, 0, n);
      System.arraycopy(ts, from, ts, 0, n);
      System.arraycopy(samples, from, samples, 0, n);
      for (int m = 0; m < n; m++) {
        int at = broke[from + m];
        broke[m] = at > from ? at - from : -1;
      }
    } else {
      Arrays.fill(broke, 0, n, -1);
    }
    count = n;
    sumX[0] = 0.0;
    sumY[0] = 0.0;
    sumXx[0] = 0.0;
    sumYy[0] = 0.0;
    sumXy[0] = 0.0;
    best[0] = 0.0;
    brief[0] = 0;
    before[0] = -1;
    errorsEnd = -1;
    double ax = xs[0];
    double ay = ys[0];
    addSums(1, 0.0, 0.0);
    for (int k = 1; k < n; k++) {
      addSums(k + 1, xs[k] - ax, ys[k] - ay);
      place(k);
    }
  }

  /** The running sums to sample at - 1, from those to the sample before and its (rx, ry). */
  private void addSums(int at, double rx, double ry) {
    sumX[at] = sumX[at - 1] + rx;
    sumY[at] = sumY[at - 1] + ry;
    sumXx[at] = sumXx[at - 1] + rx * rx;
    sumYy[at] = sumYy[at - 1] + ry * ry;
    sumXy[at] = sumXy[at - 1] + rx * ry;
  }

  private void append(double x, double y, double t, Sample sample) {
    int k = count;
    put(k, x, y, t, sample);
    broke[k] = -1;
    count = k + 1;
    addSums(k + 1, x - xs[0], y - ys[0]);
    place(k);
  }

  /** Each piece's error to sample k, from every start it may have (into errors, kept for the
   * sample until the next): the first start. */
  private int errorsTo(int k) {
    int low = Math.max(0, k - maxWindow);
    // No piece outlasts the latency cap, but one between two samples drawn further apart.
    if (maxStrokeMs > 0.0) {
      double tK = ts[k];
      while (low < k - 1 && tK - ts[low] > maxStrokeMs) {
        low++;
      }
    }
    if (errorsEnd == k) {
      return low;
    }
    for (int i = low; i < k; i++) {
      errors[i - low] = pieceError(i, k);
    }
    errorsEnd = k;
    return low;
  }

  /**
   * The best start of the last piece to sample k: the fewest pieces briefer than the floor (the
   * last counted only when closed), then the least squared error, then the earliest start; among
   * the pieces that keep the bound (the piece from k - 1 always does). Where the first choice's
   * bound breaks, the other starts are tested in the same order, sorted once (the totals are never
   * NaN). The reference's {@code _choose}.
   */
  private int choose(int k, int low, boolean closed) {
    double tK = ts[k];
    int chosen = -1;
    int chosenCount = 0;
    double chosenTotal = 0.0;
    for (int i = low; i < k; i++) {
      double total = best[i] + errors[i - low];
      int n = brief[i];
      if (closed && tK - ts[i] < floorMs) {
        n += 1;
      }
      if (chosen < 0 || n < chosenCount || (n == chosenCount && total < chosenTotal)) {
        chosen = i;
        chosenCount = n;
        chosenTotal = total;
      }
    }
    if (chosen == k - 1 || keeps(chosen, k)) {
      return chosen;
    }
    if (starts.length < k - low) {
      starts = new Integer[Math.max(k - low, starts.length * 2)];
    }
    int size = 0;
    for (int i = low; i < k; i++) {
      startCounts[i - low] = brief[i] + (closed && tK - ts[i] < floorMs ? 1 : 0);
      startTotals[i - low] = best[i] + errors[i - low];
      if (i != chosen) {
        starts[size++] = i;
      }
    }
    final int first = low;
    Arrays.sort(
        starts,
        0,
        size,
        (a, b) -> {
          int ca = startCounts[a - first];
          int cb = startCounts[b - first];
          if (ca != cb) {
            return ca < cb ? -1 : 1;
          }
          double ta = startTotals[a - first];
          double tb = startTotals[b - first];
          if (ta < tb) {
            return -1;
          }
          if (tb < ta) {
            return 1;
          }
          return Integer.compare(a, b);
        });
    for (int s = 0; s < size; s++) {
      int start = starts[s];
      if (start == k - 1 || keeps(start, k)) {
        return start;
      }
    }
    return k - 1; // (never: the piece from k - 1 is among the starts)
  }

  /** Sample k's best polyline from the anchor, every piece closed (at the floor). */
  private void place(int k) {
    int low = errorsTo(k);
    int i = choose(k, low, true);
    double total = best[i] + errors[i - low];
    int n = brief[i] + (ts[k] - ts[i] < floorMs ? 1 : 0);
    best[k] = total;
    brief[k] = n;
    before[k] = i;
  }

  /**
   * Whether every sample between xs[start] and xs[end] lies within max_error of the segment between
   * them: the sample that broke the last piece tested from start first, then the samples coarse to
   * fine (the answer is the same in any order). The reference's {@code _keeps}.
   */
  private boolean keeps(int start, int end) {
    double ax = xs[start];
    double ay = ys[start];
    double ex = xs[end];
    double ey = ys[end];
    double limitSq = maxErrorSq;
    int last = broke[start];
    if (start < last
        && last < end
        && WindowCore.distanceSq(xs[last], ys[last], ax, ay, ex, ey) > limitSq) {
      return false;
    }
    int span = end - start;
    int step = 1;
    while (step * 2 < span) {
      step *= 2;
    }
    for (; step > 0; step /= 2) {
      for (int m = start + step; m < end; m += 2 * step) {
        if (WindowCore.distanceSq(xs[m], ys[m], ax, ay, ex, ey) > limitSq) {
          broke[start] = m;
          return false;
        }
      }
    }
    return true;
  }

  /** Lets go the best polyline (every piece closed) to sample last. */
  private void polyline(int last, List<Segment> out) {
    int pieces = 0;
    for (int v = last; v != 0; v = before[v]) {
      pieces++;
    }
    int[] vertices = new int[pieces + 1];
    int at = pieces;
    for (int v = last; v != 0; v = before[v]) {
      vertices[at--] = v;
    }
    vertices[0] = 0;
    for (int p = 0; p < pieces; p++) {
      out.add(piece(vertices[p], vertices[p + 1]));
    }
  }

  private Segment piece(int a, int b) {
    emittedInPath = true;
    double emittedAtMs = pointer != null ? pointer.tMs() : ts[b];
    return new Segment(xs[a], ys[a], xs[b], ys[b], ts[a], ts[b], emittedAtMs, null)
        .checked(minLength, minDurationMs);
  }

  /** Sample k anchors the next stroke; the samples after it are taken again. */
  private void from(int k) {
    restart(k, count - k);
  }

  /** Lets go each stroke that is final: its end drawn lookahead_ms ago, or the stroke longer
   * than the latency cap. */
  private void letGo(List<Segment> out) {
    double capMs = maxStrokeMs;
    while (true) {
      int j = count - 1;
      int still = stillFrom(j);
      if (ts[j] - ts[0] < floorMs || still == 0) {
        return;
      }
      int low = errorsTo(j);
      int last = choose(j, low, false);
      if (last == 0) {
        // One stroke from the anchor: cut by the latency cap at the sample before.
        if (capMs > 0.0
            && ts[j] - ts[0] > capMs
            && j >= 2
            && ts[j - 1] - ts[0] >= floorMs
            && j - 1 <= still
            && keeps(0, j - 1)) {
          out.add(piece(0, j - 1));
          from(j - 1);
          continue;
        }
        return;
      }
      int vertex = last;
      while (before[vertex] != 0) {
        vertex = before[vertex];
      }
      if (vertex > still
          || (ts[j] - ts[vertex] < lookaheadMs
              && !(capMs > 0.0 && ts[vertex] - ts[0] > capMs))) {
        return;
      }
      out.add(piece(0, vertex));
      from(vertex);
    }
  }

  // --- rests -----------------------------------------------------------------------------------

  /**
   * Where the pen may have been resting since: the first of the samples up to j that all lie
   * within the rest radius of sample j (with rest_ms on; j + 1 without). No stroke is let go that
   * ends after it: its end would lie inside a stop that may yet turn out a rest, and the stroke
   * would play the stop. The rest rule ends the stop once it has lasted rest_ms, or the pen moves
   * on. Python {@code FitCore._still_from}.
   */
  private int stillFrom(int j) {
    if (restMs <= 0.0) {
      return j + 1;
    }
    double x = xs[j];
    double y = ys[j];
    int k = j;
    while (k > 0) {
      double dx = xs[k - 1] - x;
      double dy = ys[k - 1] - y;
      if (!(dx * dx + dy * dy <= restSq)) { // (not ">": a NaN is a move, and ends a rest)
        break;
      }
      k--;
    }
    return k;
  }

  private void retime(double t) {
    ts[0] = t;
    Sample anchor = samples[0];
    samples[0] = new Sample(t, anchor.x(), anchor.y(), anchor.pressure());
  }

  /**
   * Whether the pen has rested rest_ms at the newest sample: its samples of the last rest_ms or
   * more all lie within the rest radius of it. The best polyline to the rest's first sample is
   * let go; the rest is not played; the anchor waits at that sample for the pen to move on.
   */
  private boolean rests(List<Segment> out) {
    int j = count - 1;
    double t = ts[j];
    if (restMs <= 0.0 || t - ts[0] < restMs) {
      return false;
    }
    double x = xs[j];
    double y = ys[j];
    int start = stillFrom(j);
    if (start == j || t - ts[start] < restMs) {
      return false;
    }
    if (start > 0) {
      polyline(start, out);
    }
    restart(start, 1);
    retime(t);
    restX = x;
    restY = y;
    resting = true;
    rested = true;
    return true;
  }

  // --- the arithmetic --------------------------------------------------------------------------

  /**
   * The integral square error of the piece xs[start] -> xs[end]: the sum of the squared distances
   * of samples start..end to the line through its ends (to its start where they coincide), from
   * the running sums (of the coordinates relative to the anchor). Never below 0 (rounding); a NaN
   * gives 0. The reference's {@code piece_error}, its operations in its order.
   */
  private double pieceError(int start, int end) {
    double ax = xs[0];
    double ay = ys[0];
    double n = (double) (end + 1 - start);
    double px = xs[start] - ax;
    double py = ys[start] - ay;
    double dx = (xs[end] - ax) - px;
    double dy = (ys[end] - ay) - py;
    double sx = sumX[end + 1] - sumX[start];
    double sy = sumY[end + 1] - sumY[start];
    // Sums of (x - px)^2, (y - py)^2 and (x - px)(y - py) over the piece's samples.
    double cxx = sumXx[end + 1] - sumXx[start] - 2.0 * px * sx + n * px * px;
    double cyy = sumYy[end + 1] - sumYy[start] - 2.0 * py * sy + n * py * py;
    double cxy = sumXy[end + 1] - sumXy[start] - px * sy - py * sx + n * px * py;
    double lengthSq = dx * dx + dy * dy;
    double error;
    if (lengthSq > 0.0) {
      error = (dx * dx * cyy + dy * dy * cxx - 2.0 * dx * dy * cxy) / lengthSq;
    } else {
      error = cxx + cyy;
    }
    return error > 0.0 ? error : 0.0;
  }
}
