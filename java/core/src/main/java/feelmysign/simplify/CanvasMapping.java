package feelmysign.simplify;

/**
 * From canvas pixels to the sleeve's grid units (a port of {@code simplify/mapping.py}).
 *
 * <p>By default the aspect ratio is kept (a circle drawn stays a circle on the skin): one scale
 * for both axes, the canvas centred on the grid. The paper stretched each axis to fill the grid;
 * {@code stretch} does the same. The float operations are the reference's, in its order, so
 * every grid point is the same to the last bit.
 */
public final class CanvasMapping {
  private final double widthPx;
  private final double heightPx;
  private final boolean stretch;
  private final double xExtent;
  private final double yExtent;
  private final double xOffset;
  private final double yOffset;
  private final double scale;

  public CanvasMapping(double widthPx, double heightPx, int columns, int rows, boolean stretch) {
    this.widthPx = widthPx;
    this.heightPx = heightPx;
    this.stretch = stretch;
    this.xExtent = columns - 1;
    this.yExtent = rows - 1;
    // Grid units per pixel when the aspect ratio is kept: the tighter axis decides.
    double s = Double.NaN;
    if (columns - 1 > 0) {
      s = (columns - 1) / widthPx;
    }
    if (rows - 1 > 0) {
      double sy = (rows - 1) / heightPx;
      s = Double.isNaN(s) ? sy : Math.min(s, sy);
    }
    this.scale = Double.isNaN(s) ? 0.0 : s;
    this.xOffset = (xExtent - widthPx * scale) / 2;
    this.yOffset = (yExtent - heightPx * scale) / 2;
  }

  /** Grid units per pixel when the aspect ratio is kept. */
  public double scale() {
    return scale;
  }

  /** The grid column of a canvas pixel's x, clamped onto the grid. */
  public double gridX(double xPx) {
    double x = stretch ? xPx * xExtent / widthPx : xOffset + xPx * scale;
    return clamp(x, xExtent);
  }

  /** The grid row of a canvas pixel's y, clamped onto the grid. */
  public double gridY(double yPx) {
    double y = stretch ? yPx * yExtent / heightPx : yOffset + yPx * scale;
    return clamp(y, yExtent);
  }

  /** min(max(v, 0.0), extent) as Python's max and min compare: a NaN stays NaN. */
  private static double clamp(double value, double extent) {
    if (value < 0.0) {
      value = 0.0;
    }
    if (extent < value) {
      value = extent;
    }
    return value;
  }
}
