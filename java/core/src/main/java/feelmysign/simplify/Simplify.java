package feelmysign.simplify;

import java.util.ArrayList;
import java.util.List;

/** A whole drawing through one simplifier, deterministically (the reference's simplify_paths). */
public final class Simplify {
  private Simplify() {}

  /**
   * Every path fed to the simplifier {@code params} belongs to (as frames or samples, see
   * {@link Algorithm#takesFrames}) and ended.
   */
  public static List<PathSegment> paths(Params params, List<List<Sample>> paths) {
    Algorithm algorithm = params.algorithm();
    Simplifier simplifier = algorithm.make(params);
    List<PathSegment> out = new ArrayList<>();
    for (int index = 0; index < paths.size(); index++) {
      for (Sample item : algorithm.inputs(params, paths.get(index))) {
        for (Segment s : simplifier.push(item)) {
          out.add(new PathSegment(index, s));
        }
      }
      for (Segment s : simplifier.end()) {
        out.add(new PathSegment(index, s));
      }
    }
    return out;
  }
}
