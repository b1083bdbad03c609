package feelmysign.simplify;

import java.util.ArrayList;
import java.util.List;

/**
 * The angle simplifier: the online algorithm of "Can You Feel My Sign?" (section 4.4, B.4), a
 * port of the reference {@code simplify/angle.py} that reproduces {@code testdata/angle/}.
 *
 * <p>Every {@code check_frames} frames it compares the direction of the line drawn so far (start
 * to pointer) with the direction of the latest movement (pointer at the last check to pointer).
 * When they differ by more than {@code max_angle_deg} the line up to the last check is finished
 * and a new one begins there. Where the paper's pseudo-code is ambiguous the readings of the
 * reference are taken (docs/research.md): counters start at zero on press; with
 * {@code recover} a failed check starts the new line at the last check; {@code frame_max} cuts
 * the line at the pointer; on release a last check decides whether the rest is one line or two;
 * a finished line too short or too brief is dropped with its reason. The float operations follow
 * the reference's order.
 */
public final class AngleSimplifier implements Simplifier {
  /** Movements shorter than this (pixels) have no direction. */
  static final double STILL_PX = 1e-9;

  private final Params params;
  private final int checkFrames;
  private final int frameMax;
  private final boolean recover;
  private final double minLength;
  private final double minDurationMs;
  private final double cosMax;
  private final CanvasMapping mapping;
  private Line line;
  private Sample pointer;

  /** The line being drawn: where it starts and where its last passed check was. */
  private static final class Line {
    Sample start;
    Sample last;
    int framesSinceCheck;
    int framesInLine;

    Line(Sample start) {
      this.start = start;
      this.last = start;
    }
  }

  public AngleSimplifier(Params params) {
    if (params.algorithm() != Algorithm.ANGLE) {
      throw new IllegalArgumentException("the angle simplifier needs Params.angle()");
    }
    this.params = params;
    this.checkFrames = params.integer("check_frames");
    this.frameMax = params.integer("frame_max");
    this.recover = params.flag("recover");
    this.minLength = params.number("min_length");
    this.minDurationMs = params.number("min_duration_ms");
    // Python's math.radians multiplies by pi/180 computed first; fdlibm's cos, not an intrinsic.
    this.cosMax = StrictMath.cos(params.number("max_angle_deg") * (Math.PI / 180.0));
    this.mapping = params.mapping();
  }

  public Params params() {
    return params;
  }

  @Override
  public boolean drawing() {
    return line != null;
  }

  @Override
  public Sample lineStart() {
    return line == null ? null : line.start;
  }

  @Override
  public List<Segment> push(Sample frame) {
    pointer = frame;
    Line current = line;
    if (current == null) {
      line = new Line(frame);
      return List.of();
    }
    List<Segment> out = new ArrayList<>(2);
    current.framesSinceCheck++;
    current.framesInLine++;
    if (current.framesSinceCheck >= checkFrames) {
      check(current, frame, out);
    }
    if (frameMax != 0 && current.framesInLine > frameMax) {
      out.add(finish(current.start, frame));
      line = new Line(frame);
    }
    return out;
  }

  @Override
  public List<Segment> end() {
    Line current = line;
    Sample at = pointer;
    line = null;
    if (current == null || at == null) {
      return List.of();
    }
    // Identity, as in the reference: `last` is `start` until a check has passed.
    if (current.last != current.start && turned(current, at)) {
      return List.of(finish(current.start, current.last), finish(current.last, at));
    }
    return List.of(finish(current.start, at));
  }

  private void check(Line current, Sample frame, List<Segment> out) {
    if (turned(current, frame)) {
      out.add(finish(current.start, current.last));
      if (recover) {
        current.start = current.last;
        current.framesInLine = current.framesSinceCheck;
      } else {
        current.start = frame;
        current.framesInLine = 0;
      }
    }
    current.last = frame;
    current.framesSinceCheck = 0;
  }

  /** Whether start -> frame and last check -> frame differ by more than the maximum angle. */
  private boolean turned(Line current, Sample frame) {
    double ux = frame.x() - current.start.x();
    double uy = frame.y() - current.start.y();
    double vx = frame.x() - current.last.x();
    double vy = frame.y() - current.last.y();
    double moved = Math.sqrt(vx * vx + vy * vy);
    if (moved <= STILL_PX) {
      return false; // the pointer rested since the last check: no new direction
    }
    double lineSoFar = Math.sqrt(ux * ux + uy * uy);
    if (lineSoFar <= STILL_PX) {
      return true; // it moved, back onto the line's start: a full reversal
    }
    return (ux * vx + uy * vy) / (lineSoFar * moved) < cosMax;
  }

  private Segment finish(Sample start, Sample end) {
    double emittedAtMs = pointer != null ? pointer.tMs() : end.tMs();
    return new Segment(
            mapping.gridX(start.x()),
            mapping.gridY(start.y()),
            mapping.gridX(end.x()),
            mapping.gridY(end.y()),
            start.tMs(),
            end.tMs(),
            emittedAtMs,
            null)
        .checked(minLength, minDurationMs);
  }
}
