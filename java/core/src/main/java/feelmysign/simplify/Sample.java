package feelmysign.simplify;

/** One pointer reading: canvas pixels (origin top-left, y down), ms, pressure 0..1. */
public record Sample(double tMs, double x, double y, double pressure) {
  /** A reading without pressure (0.5, as the reference assumes). */
  public Sample(double tMs, double x, double y) {
    this(tMs, x, y, 0.5);
  }
}
