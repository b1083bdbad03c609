package feelmysign.shapes;

import feelmysign.protocol.Stroke;
import feelmysign.simplify.ParameterException;
import java.math.BigDecimal;
import java.math.RoundingMode;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.IntFunction;

/**
 * The reference's library of shapes drawn as strokes ({@code feelmysign/shapes.py}): circle,
 * square, triangle, star, heart, line, at a chosen number of strokes (the resolution of the
 * paper's section 6 study: a circle of 3 segments is a triangle, of 64 a smooth circle). Each
 * is one continuous line sized to fill the grid with equal scale on x and y, centred, drawn at
 * a steady speed. The same vertices and durations as the reference.
 */
public final class Shapes {
  /** A steady hand on the forearm: 5 cm/s (the reference's DRAWING_SPEED_CM_S). */
  public static final double DRAWING_SPEED_CM_S = 5.0;
  public static final int MAX_SEGMENTS = 64;
  public static final int COORDINATE_DECIMALS = 6;
  public static final int DURATION_DECIMALS = 3;
  private static final int OUTLINE_SAMPLES = 4096;

  private Shapes() {}

  /** How many strokes a shape may have. */
  public record Spec(String name, String description, int defaultSegments, int minSegments,
      int maxSegments, int step) {
    public String allowed() {
      if (step == 1) {
        return "a whole number from " + minSegments + " to " + maxSegments;
      }
      return "a multiple of " + step + " from " + minSegments + " to " + maxSegments
          + " (each of its " + step + " sides split into equal strokes)";
    }

    public boolean accepts(int segments) {
      return minSegments <= segments && segments <= maxSegments
          && (segments - minSegments) % step == 0;
    }
  }

  /** The shapes by name, in the reference's order. */
  public static final Map<String, Spec> SHAPES = new LinkedHashMap<>();

  static {
    add(new Spec("circle", "a circle, from the top, counter-clockwise", 16, 3, MAX_SEGMENTS, 1));
    add(new Spec("square", "a square, from the top-left corner, down first", 4, 4,
        below(4, MAX_SEGMENTS), 4));
    add(new Spec("triangle", "an upright equilateral triangle, from its apex", 3, 3,
        below(3, MAX_SEGMENTS), 3));
    add(new Spec("star", "a five-pointed star in one line, from the top point", 5, 5,
        below(5, MAX_SEGMENTS), 5));
    add(new Spec("heart", "a heart, from the dip at the top, left lobe first", 16, 3,
        MAX_SEGMENTS, 1));
    add(new Spec("line", "a horizontal line through the middle, left to right", 1, 1,
        MAX_SEGMENTS, 1));
  }

  private static void add(Spec spec) {
    SHAPES.put(spec.name(), spec);
  }

  private static int below(int step, int limit) {
    return limit - limit % step;
  }

  /** The spec of {@code name}; a ParameterException listing the shapes for an unknown one. */
  public static Spec spec(String name) {
    Spec spec = SHAPES.get(name);
    if (spec == null) {
      throw new ParameterException("shape", name, "one of " + String.join(", ", SHAPES.keySet()));
    }
    return spec;
  }

  /**
   * The strokes of shape {@code name} on a {@code rows} x {@code columns} grid, {@code
   * spacingCm} apart, whose sleeve plays strokes up to {@code maxStrokeMs}.
   *
   * @param segments number of strokes, null for the shape's default
   * @param durationMs the whole shape's duration, null to draw it at {@link #DRAWING_SPEED_CM_S}
   * @param margin grid units kept free on every side
   * @throws ParameterException naming the value and its range, in the reference's words
   */
  public static List<Stroke> strokes(String name, int rows, int columns, double spacingCm,
      double maxStrokeMs, Integer segments, Double durationMs, double margin) {
    Spec spec = spec(name);
    int count = segments == null ? spec.defaultSegments() : segments;
    if (!spec.accepts(count)) {
      throw new ParameterException("segments of a " + spec.name(), (long) count, spec.allowed());
    }
    List<double[]> vertices =
        fit(OUTLINES.get(name).apply(count), IDEAL_BOXES.get(name), rows, columns, margin);
    double[] lengths = new double[count];
    double total = 0;
    for (int i = 0; i < count; i++) {
      lengths[i] = dist(vertices.get(i), vertices.get(i + 1));
      total += lengths[i];
    }
    double totalMs;
    if (durationMs == null) {
      totalMs = total * spacingCm / DRAWING_SPEED_CM_S * 1000.0;
    } else if (!(Double.isFinite(durationMs) && durationMs > 0)) {
      throw new ParameterException("duration_ms", durationMs, "a number of milliseconds above 0");
    } else {
      totalMs = durationMs;
    }
    double[] durations = new double[count];
    double longest = 0;
    for (int i = 0; i < count; i++) {
      durations[i] = round(totalMs * lengths[i] / total, DURATION_DECIMALS);
      longest = Math.max(longest, durations[i]);
    }
    if (longest > maxStrokeMs) {
      double mostMs = totalMs / longest * maxStrokeMs;
      throw new ParameterException("duration_ms of this " + spec.name(), round(totalMs, 3),
          "at most " + (long) Math.floor(mostMs) + " ms: its longest stroke would last "
              + Math.round(longest) + " ms, above the layout's max_stroke_duration_ms "
              + new BigDecimal(maxStrokeMs).stripTrailingZeros().toPlainString()
              + "; shorten it or use more segments");
    }
    List<Stroke> out = new ArrayList<>(count);
    for (int i = 0; i < count; i++) {
      double[] a = vertices.get(i);
      double[] b = vertices.get(i + 1);
      out.add(new Stroke(a[0], a[1], b[0], b[1], durations[i]));
    }
    return out;
  }

  /** Python's round(value, decimals): the exact binary value, halves to even. */
  static double round(double value, int decimals) {
    return new BigDecimal(value).setScale(decimals, RoundingMode.HALF_EVEN).doubleValue();
  }

  private static double dist(double[] a, double[] b) {
    return Math.hypot(b[0] - a[0], b[1] - a[1]);
  }

  // ---- outlines: vertices in a unit frame, x right, y down ----

  private static List<double[]> around(int count, double startDeg, double stepDeg) {
    List<double[]> points = new ArrayList<>();
    for (int k = 0; k < count; k++) {
      double angle = Math.toRadians(startDeg + k * stepDeg);
      points.add(new double[] {Math.sin(angle), -Math.cos(angle)});
    }
    points.add(points.get(0));
    return points;
  }

  private static List<double[]> subdivide(List<double[]> corners, int perSide) {
    List<double[]> points = new ArrayList<>();
    for (int i = 0; i + 1 < corners.size(); i++) {
      double[] a = corners.get(i);
      double[] b = corners.get(i + 1);
      for (int k = 0; k < perSide; k++) {
        double t = (double) k / perSide;
        points.add(new double[] {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t});
      }
    }
    points.add(corners.get(corners.size() - 1));
    return points;
  }

  private static List<double[]> heartOutline() {
    List<double[]> points = new ArrayList<>();
    for (int j = 0; j <= OUTLINE_SAMPLES; j++) {
      double t = 2.0 * Math.PI * j / OUTLINE_SAMPLES;
      double x = -16.0 * Math.pow(Math.sin(t), 3);
      double yUp = 13.0 * Math.cos(t) - 5.0 * Math.cos(2 * t) - 2.0 * Math.cos(3 * t)
          - Math.cos(4 * t);
      points.add(new double[] {x, -yUp});
    }
    return points;
  }

  private static List<double[]> heart(int count) {
    List<double[]> outline = heartOutline();
    double[] cumulative = new double[outline.size()];
    for (int i = 1; i < outline.size(); i++) {
      cumulative[i] = cumulative[i - 1] + dist(outline.get(i - 1), outline.get(i));
    }
    double total = cumulative[cumulative.length - 1];
    List<double[]> points = new ArrayList<>();
    int j = 0;
    for (int k = 0; k < count; k++) {
      double target = total * k / count;
      while (cumulative[j + 1] < target) {
        j++;
      }
      double span = cumulative[j + 1] - cumulative[j];
      double t = span > 0 ? (target - cumulative[j]) / span : 0.0;
      double[] a = outline.get(j);
      double[] b = outline.get(j + 1);
      points.add(new double[] {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t});
    }
    points.add(points.get(0));
    return points;
  }

  private static final Map<String, IntFunction<List<double[]>>> OUTLINES = Map.of(
      "circle", count -> around(count, 0.0, -360.0 / count),
      "square", count -> subdivide(List.of(new double[] {-1, -1}, new double[] {-1, 1},
          new double[] {1, 1}, new double[] {1, -1}, new double[] {-1, -1}), count / 4),
      "triangle", count -> subdivide(around(3, 0.0, -120.0), count / 3),
      "star", count -> subdivide(around(5, 0.0, -144.0), count / 5),
      "heart", Shapes::heart,
      "line", count -> {
        List<double[]> points = new ArrayList<>();
        for (int k = 0; k <= count; k++) {
          points.add(new double[] {-1.0 + 2.0 * k / count, 0.0});
        }
        return points;
      });

  private static double[] box(List<double[]> points) {
    double[] b = {Double.POSITIVE_INFINITY, Double.POSITIVE_INFINITY,
        Double.NEGATIVE_INFINITY, Double.NEGATIVE_INFINITY};
    for (double[] p : points) {
      b[0] = Math.min(b[0], p[0]);
      b[1] = Math.min(b[1], p[1]);
      b[2] = Math.max(b[2], p[0]);
      b[3] = Math.max(b[3], p[1]);
    }
    return b;
  }

  private static final Map<String, double[]> IDEAL_BOXES = Map.of(
      "circle", new double[] {-1, -1, 1, 1},
      "square", new double[] {-1, -1, 1, 1},
      "triangle", box(OUTLINES.get("triangle").apply(3)),
      "star", box(OUTLINES.get("star").apply(5)),
      "heart", box(heartOutline()),
      "line", new double[] {-1, 0, 1, 0});

  private static List<double[]> fit(List<double[]> points, double[] box, int rows, int columns,
      double margin) {
    double width = box[2] - box[0];
    double height = box[3] - box[1];
    boolean needsHeight = height > 0;
    if (!(Double.isFinite(margin) && margin >= 0)) {
      throw new ParameterException("margin", margin, "0 or more grid units");
    }
    double spanX = columns - 1.0;
    double spanY = rows - 1.0;
    check("columns", spanX, margin, rows, columns);
    if (needsHeight) {
      check("rows", spanY, margin, rows, columns);
    }
    double roomX = spanX - 2 * margin;
    double roomY = spanY - 2 * margin;
    double scale = needsHeight ? Math.min(roomX / width, roomY / height) : roomX / width;
    double centreX = (columns - 1) / 2.0;
    double centreY = (rows - 1) / 2.0;
    double midX = (box[0] + box[2]) / 2;
    double midY = (box[1] + box[3]) / 2;
    List<double[]> out = new ArrayList<>(points.size());
    for (double[] p : points) {
      double x = Math.min(Math.max(centreX + (p[0] - midX) * scale, 0.0), columns - 1.0);
      double y = Math.min(Math.max(centreY + (p[1] - midY) * scale, 0.0), rows - 1.0);
      out.add(new double[] {round(x, COORDINATE_DECIMALS), round(y, COORDINATE_DECIMALS)});
    }
    return out;
  }

  private static void check(String what, double span, double margin, int rows, int columns) {
    if (span <= 0) {
      throw new ParameterException("layout", rows + " x " + columns,
          "a grid of at least 2 " + what + " for this shape (only 'line' needs no height)");
    }
    if (span - 2 * margin <= 0) {
      throw new ParameterException("margin", margin, "less than "
          + new BigDecimal(span / 2).stripTrailingZeros().toPlainString() + " (grid units) on this "
          + rows + " x " + columns + " grid, or nothing is left to draw in");
    }
  }
}
