package feelmysign.processing;

import feelmysign.simplify.Sample;
import java.util.ArrayList;
import java.util.List;

/**
 * {@link feelmysign.simplify.Frames#fromSamples} as the samples arrive: one frame every 1000/fps
 * ms from the press, holding the latest sample seen, the release last. Fed the same samples it
 * gives the same frames, so a sketch sends what {@code feelmysign simplify} computes from a
 * recording of the same mouse path.
 */
final class LiveFrames {
  private final double periodMs;
  private Sample first;
  private Sample held;
  private Sample latest;
  private long nextK;
  /** Whether the latest sample has been held by a frame (or is the press). */
  private boolean latestFramed;

  LiveFrames(double fps) {
    this.periodMs = 1000.0 / fps;
  }

  /** The press: the first frame. */
  List<Sample> press(Sample sample) {
    first = sample;
    held = sample;
    latest = sample;
    latestFramed = true;
    nextK = 1;
    List<Sample> out = new ArrayList<>(1);
    out.add(sample);
    return out;
  }

  /** A move: the frames due strictly before it, each holding the sample seen by then. */
  List<Sample> move(Sample sample) {
    List<Sample> out = new ArrayList<>();
    // Frames at or after the new sample's time may hold it (or a later one): wait for those.
    framesUpTo(sample.tMs(), false, out);
    held = sample;
    latest = sample;
    latestFramed = false;
    return out;
  }

  /** The release (its sample already given to {@link #move}): the last frames. */
  List<Sample> release() {
    List<Sample> out = new ArrayList<>();
    framesUpTo(latest.tMs(), true, out);
    if (!latestFramed) {
      out.add(latest);
    }
    first = null;
    return out;
  }

  private void framesUpTo(double limitMs, boolean inclusive, List<Sample> out) {
    for (; ; nextK++) {
      double tMs = first.tMs() + nextK * periodMs;
      if (inclusive ? tMs > limitMs : tMs >= limitMs) {
        return;
      }
      out.add(new Sample(tMs, held.x(), held.y(), held.pressure()));
      if (held == latest) {
        latestFramed = true;
      }
    }
  }
}
