package feelmysign.client;

import feelmysign.json.Numbers;
import feelmysign.simplify.Params;
import java.math.BigDecimal;
import java.math.RoundingMode;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;

/**
 * The sleeve's floor, as its retained status carries it ({@code floor}, docs/protocol.md): the
 * least a stroke should be for this sleeve to play it as sent and its wearer to feel it. The
 * mirror of Python {@code feelmysign.events.StatusFloor} and {@code wearer.respect_floor}, and of
 * the page's {@code SleeveFloor} and {@code withFloor} (web/src/sleeve-floor.ts).
 *
 * @param minDurationMs the shortest stroke the sleeve plays without slowing it (73.701 ms on the
 *     paper's ERM motors), or the wearer's measured shortest felt duration when that is longer
 * @param minLength the shortest stroke felt as moving, in grid units
 * @param wearer whose measured limits are in it; null without a wearer
 */
public record SleeveFloor(double minDurationMs, double minLength, String wearer) {
  /** The largest floor duration taken as one (the simplifier's own limit on its minimums). */
  public static final double MAX_DURATION_MS = 10_000;
  /** The largest floor length taken as one, in grid units (the simplifier's limit). */
  public static final double MAX_LENGTH = 100;

  /** Checked when made: what {@link #read} refuses cannot be made either. */
  public SleeveFloor {
    String problem = problem(minDurationMs, minLength);
    if (problem != null) {
      throw new IllegalArgumentException(problem);
    }
    if (wearer != null && wearer.isEmpty()) {
      wearer = null; // no name is no wearer, as the reference reads it
    }
  }

  /** Whether a wearer's measured limits are in it (then a sender keeps to them strictly). */
  public boolean hasWearer() {
    return wearer != null;
  }

  /** What is in a status's {@code floor}: a floor, none, or one not understood (with why). */
  public sealed interface Read {}

  /** The status says a floor. */
  public record Said(SleeveFloor floor) implements Read {}

  /** The status has no floor ({@code floor} absent or null: a sleeve older than it). */
  public record Absent() implements Read {}

  /** The status's floor is not one: {@code problem} says what is wrong with it. */
  public record NotUnderstood(String problem) implements Read {}

  /** The {@code floor} of a status decoded from JSON (the value of its key, null when absent). */
  public static Read read(Object value) {
    if (value == null) {
      return new Absent();
    }
    if (!(value instanceof Map<?, ?> fields)) {
      return new NotUnderstood("it is not an object");
    }
    Double duration = number(fields.get("min_duration_ms"));
    Double length = number(fields.get("min_length"));
    if (duration == null || length == null) {
      return new NotUnderstood("min_duration_ms and min_length must be numbers");
    }
    Object wearer = fields.get("wearer");
    if (wearer != null && !(wearer instanceof String)) {
      return new NotUnderstood("wearer must be a name (text)");
    }
    String problem = problem(duration, length);
    if (problem != null) {
      return new NotUnderstood(problem);
    }
    return new Said(new SleeveFloor(duration, length, (String) wearer));
  }

  private static Double number(Object value) {
    if (value instanceof Long l) {
      return (double) l;
    }
    return value instanceof Double d ? d : null;
  }

  private static String problem(double durationMs, double length) {
    if (!(Double.isFinite(durationMs) && durationMs > 0 && durationMs <= MAX_DURATION_MS)) {
      return "min_duration_ms " + Numbers.pythonG(durationMs) + " is not a duration above 0 and"
          + " at most " + Numbers.pythonG(MAX_DURATION_MS) + " ms";
    }
    if (!(Double.isFinite(length) && length >= 0 && length <= MAX_LENGTH)) {
      return "min_length " + Numbers.pythonG(length) + " is not a length from 0 to "
          + Numbers.pythonG(MAX_LENGTH) + " grid units";
    }
    return null;
  }

  /**
   * {@code own} as a sender keeps to this floor (docs/protocol.md, {@code floor}): the window
   * simplifier merges a piece briefer than the floor into the next where every drawn sample keeps
   * {@code max_error} ({@code floor_ms}); with a wearer's limits, {@code min_duration_ms} and
   * {@code min_length} are raised to at least the floor's (never lowered) and kept to even where
   * {@code max_error} must yield ({@code strict_minimums}). The motors' floor alone raises no
   * minimum: a simplifier drops a piece below its minimums, which costs more of a shape than the
   * sleeve's slowing it. The same {@code own} when nothing changes.
   */
  public Params applyTo(Params own) {
    Params out = own;
    if (own.values().containsKey("floor_ms") && own.values().containsKey("strict_minimums")) {
      if (own.number("floor_ms") != minDurationMs || own.flag("strict_minimums") != hasWearer()) {
        out = out.with("floor_ms", minDurationMs).with("strict_minimums", hasWearer());
      }
    }
    if (!hasWearer()) {
      return out;
    }
    if (minDurationMs > own.number("min_duration_ms")) {
      out = out.with("min_duration_ms", minDurationMs);
    }
    if (minLength > own.number("min_length")) {
      out = out.with("min_length", minLength);
    }
    return out;
  }

  /**
   * One sentence: what this floor makes a simplifier with {@code own} parameters use, in the
   * page's words (its settings panel, web/src/sleeve-floor.ts {@code floorNote}).
   */
  public String note(Params own) {
    if (!hasWearer()) {
      return "The sleeve plays strokes briefer than " + rounded(minDurationMs) + " ms slowed to"
          + " that, and catches up after them; a wearer file (feelmysign sleeve --wearer) sets"
          + " limits the sketch keeps to.";
    }
    List<String> raised = new ArrayList<>();
    if (minDurationMs > own.number("min_duration_ms")) {
      raised.add("min duration");
    }
    if (minLength > own.number("min_length")) {
      raised.add("min length");
    }
    String effect = raised.isEmpty()
        ? "your settings are above it"
        : String.join(" and ", raised) + " raised to it";
    return "At least " + rounded(minDurationMs) + " ms and " + rounded(minLength)
        + " grid units per stroke: the sleeve's floor with wearer " + wearer + "'s limits; "
        + effect + ".";
  }

  /**
   * One line for a command that raised {@code own}'s minimums to this floor (Python {@code
   * respect_floor}'s, as {@code feelmysign replay --send} says it); null when nothing was raised.
   */
  public String raisedNote(Params own) {
    if (!hasWearer()) {
      return null;
    }
    List<String> raised = new ArrayList<>();
    if (minDurationMs > own.number("min_duration_ms")) {
      raised.add("min duration " + Numbers.pythonG(minDurationMs) + " ms");
    }
    if (minLength > own.number("min_length")) {
      raised.add("min length " + Numbers.pythonG(minLength) + " grid units");
    }
    if (raised.isEmpty()) {
      return null;
    }
    return "Raised " + String.join(" and ", raised) + ": the sleeve's floor with wearer " + wearer
        + "'s limits.";
  }

  /** At most two decimals, no trailing zeros (118.4, 0.62, 73.7): the page's rounding. */
  static String rounded(double value) {
    return BigDecimal.valueOf(value).setScale(2, RoundingMode.HALF_UP).stripTrailingZeros()
        .toPlainString();
  }
}
