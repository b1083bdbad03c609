package feelmysign.simplify;

import java.util.ArrayList;
import java.util.List;

/** Animation frames from recorded samples: what a drawing loop at {@code fps} would have seen. */
public final class Frames {
  private Frames() {}

  /**
   * One frame every 1000/fps ms from the first sample, holding the latest sample seen. The first
   * sample (the press) is the first frame and the last sample (the release) the last, so a
   * path's ends are never lost between two frames.
   */
  public static List<Sample> fromSamples(List<Sample> samples, double fps) {
    List<Sample> frames = new ArrayList<>();
    if (samples.isEmpty()) {
      return frames;
    }
    double periodMs = 1000.0 / fps;
    Sample first = samples.get(0);
    Sample last = samples.get(samples.size() - 1);
    double t0 = first.tMs();
    frames.add(first);
    int index = 0;
    // t0 + k * period, not an accumulated sum: the reference's rounding.
    for (long k = 1; ; k++) {
      double tMs = t0 + k * periodMs;
      if (tMs > last.tMs()) {
        break;
      }
      while (index + 1 < samples.size() && samples.get(index + 1).tMs() <= tMs) {
        index++;
      }
      Sample held = samples.get(index);
      frames.add(new Sample(tMs, held.x(), held.y(), held.pressure()));
    }
    if (index < samples.size() - 1) {
      frames.add(last);
    }
    return frames;
  }
}
