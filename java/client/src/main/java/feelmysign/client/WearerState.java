package feelmysign.client;

import feelmysign.json.JsonDecodeException;
import feelmysign.json.NonFiniteLiteralException;
import feelmysign.json.PyJson;
import java.time.Instant;
import java.time.ZoneId;
import java.time.format.DateTimeFormatter;
import java.util.Map;

/**
 * The wearer's choice, as the sleeve's retained status carries it ({@code controls},
 * docs/protocol.md): paused, an intensity ceiling, "do not disturb" until a time. The wearer's
 * choice always wins over the sender's: a paused sleeve refuses every stroke ({@code paused}), one
 * in "do not disturb" every stroke until its end ({@code do_not_disturb}), and the ceiling caps
 * every stroke's intensity. A status without {@code controls} (an older sleeve, a last will)
 * means none of them ({@link #NONE}). The mirror of Python {@code feelmysign.wearer_status} and
 * web/src/wearer-status.ts.
 *
 * @param paused the wearer paused the sleeve
 * @param pausedBy who paused ("button", "page", "cli"); null when not paused
 * @param ceiling the wearer's intensity ceiling, 0..1; null: none
 * @param doNotDisturbUntilMs wall clock, ms since 1970; null: off
 */
public record WearerState(
    boolean paused, String pausedBy, Double ceiling, Long doNotDisturbUntilMs) {

  /** The refusal reasons of strokes the wearer's choice kept from playing. */
  public static final String PAUSED = "paused";

  public static final String DO_NOT_DISTURB = "do_not_disturb";

  /** What a status without {@code controls} means: not paused, no ceiling, no "do not disturb". */
  public static final WearerState NONE = new WearerState(false, null, null, null);

  private static final DateTimeFormatter CLOCK = DateTimeFormatter.ofPattern("HH:mm");

  /**
   * The wearer's state in a status payload: {@link #NONE} when it has no {@code controls}; null
   * when the payload is not a JSON object or a field of {@code controls} has the wrong type (as
   * {@link SleeveEvent#parse} gives null for what is not an event).
   */
  public static WearerState parse(String statusPayload) {
    Object document;
    try {
      document = PyJson.loads(statusPayload);
    } catch (JsonDecodeException | NonFiniteLiteralException error) {
      return null;
    }
    if (!(document instanceof Map<?, ?> status)) {
      return null;
    }
    Object controls = status.get("controls");
    if (controls == null) {
      return NONE;
    }
    if (!(controls instanceof Map<?, ?> fields) || !(fields.get("paused") instanceof Boolean paused)) {
      return null;
    }
    Object by = fields.get("paused_by");
    Object ceiling = fields.get("ceiling");
    Object until = fields.get("do_not_disturb_until_ms");
    if (by != null && !(by instanceof String)) {
      return null;
    }
    Double ceilingValue = ceiling == null ? null : fraction(ceiling);
    Long untilValue = until == null ? null : wholeMs(until);
    if ((ceiling != null && ceilingValue == null) || (until != null && untilValue == null)) {
      return null;
    }
    return new WearerState(paused, paused ? (String) by : null, ceilingValue, untilValue);
  }

  private static Double fraction(Object value) {
    double number;
    if (value instanceof Long l) {
      number = l;
    } else if (value instanceof Double d) {
      number = d;
    } else {
      return null;
    }
    return number >= 0 && number <= 1 ? number : null;
  }

  /** 3.0 is 3 (JavaScript cannot tell them apart), as for a seq. */
  private static Long wholeMs(Object value) {
    if (value instanceof Long l && l >= 0) {
      return l;
    }
    if (value instanceof Double d && d >= 0 && d == Math.rint(d) && d <= 9.007199254740991E15) {
      return (long) (double) d;
    }
    return null;
  }

  /** Whether "do not disturb" runs at {@code nowMs} (wall clock): it ends by itself. */
  public boolean doNotDisturb(long nowMs) {
    return doNotDisturbUntilMs != null && doNotDisturbUntilMs > nowMs;
  }

  /** Whether the sleeve refuses every stroke at {@code nowMs}: paused, or "do not disturb". */
  public boolean holds(long nowMs) {
    return paused || doNotDisturb(nowMs);
  }

  /** What the sleeve plays for a stroke sent at {@code intensity}: no more than the ceiling. */
  public double playedIntensity(double intensity) {
    return ceiling == null ? intensity : Math.min(intensity, ceiling);
  }

  /**
   * One sentence for a person: what the wearer chose and what to do, times in {@code zone}; null
   * when the wearer chose nothing.
   */
  public String sentence(long nowMs, ZoneId zone) {
    if (paused) {
      return "the wearer paused the sleeve: strokes are refused until the wearer resumes it; "
          + "wait for the wearer" + ceilingClause();
    }
    if (doNotDisturb(nowMs)) {
      String until = CLOCK.format(Instant.ofEpochMilli(doNotDisturbUntilMs).atZone(zone));
      return "the wearer asked not to be disturbed until " + until
          + ": strokes are refused until then" + ceilingClause();
    }
    if (ceiling != null) {
      return "the wearer set a ceiling of " + Math.round(ceiling * 100) + " %: the sleeve plays "
          + "no stroke stronger than that";
    }
    return null;
  }

  /**
   * What holds the sleeve at {@code nowMs} and what to do, for a command that sent nothing: the
   * Python CLI's sentence ({@code feelmysign.wearer_status.hold_sentence}); null when nothing holds.
   */
  public String holdSentence(String sleeveId, long nowMs, ZoneId zone) {
    if (paused) {
      return "The wearer paused sleeve '" + sleeveId + "': it plays nothing and refuses every"
          + " stroke until the wearer resumes it (their button or the wearer's page). Nothing was"
          + " sent; send again once the wearer has resumed.";
    }
    if (doNotDisturb(nowMs)) {
      String until = CLOCK.format(Instant.ofEpochMilli(doNotDisturbUntilMs).atZone(zone));
      return "The wearer of sleeve '" + sleeveId + "' asked not to be disturbed until " + until
          + ": it refuses every stroke until then. Nothing was sent; send again after " + until
          + ", or once the wearer has ended it.";
    }
    return null;
  }

  private String ceilingClause() {
    return ceiling == null ? "" : " (and a ceiling of " + Math.round(ceiling * 100) + " %)";
  }
}
