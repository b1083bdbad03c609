package feelmysign.simplify;

import java.util.List;

/**
 * An online simplifier: pointer input in, straight strokes (grid units) out. Pure and
 * streaming: {@link #push} one frame or sample while the pointer is down (the first of a path
 * is the press), {@link #end} on release; both return the segments finished by that call.
 */
public interface Simplifier {
  List<Segment> push(Sample input);

  List<Segment> end();

  /** True between the first input of a path and {@link #end}. */
  boolean drawing();

  /** Where the line being drawn starts (canvas pixels), for showing it; null between paths. */
  Sample lineStart();
}
