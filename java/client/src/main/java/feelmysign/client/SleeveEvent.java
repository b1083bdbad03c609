package feelmysign.client;

import feelmysign.json.JsonDecodeException;
import feelmysign.json.NonFiniteLiteralException;
import feelmysign.json.PyJson;
import java.util.Map;

/**
 * One message on a sleeve's {@code events} topic (docs/protocol.md, "Events"): a stroke
 * {@code played}, {@code adjusted} (slowed to be felt), {@code rejected} (with its reason),
 * {@code cancelled} (by the wearer when {@link #byWearer()}), or a {@code safety} or {@code error}
 * report. {@code fields} holds every field as sent.
 */
public record SleeveEvent(
    String type, String drawing, Long seq, String reason, String message, Map<String, Object> fields) {

  public static final String PLAYED = "played";
  public static final String ADJUSTED = "adjusted";
  public static final String REJECTED = "rejected";
  public static final String CANCELLED = "cancelled";
  public static final String SAFETY = "safety";
  public static final String ERROR = "error";
  /** The refusal reasons of the wearer's controls: paused, and "do not disturb" until a time. */
  public static final String PAUSED = "paused";
  public static final String DO_NOT_DISTURB = "do_not_disturb";
  /** The {@code by} of a stroke the wearer's pause or stop cut. */
  public static final String BY_WEARER = "wearer";

  /** Whether the wearer's pause or stop cut this stroke (a {@code cancelled} event by the wearer). */
  public boolean byWearer() {
    return CANCELLED.equals(type) && BY_WEARER.equals(fields.get("by"));
  }

  /** Whether the wearer's controls refused this stroke ({@code paused} or {@code do_not_disturb}). */
  public boolean refusedByWearer() {
    return REJECTED.equals(type) && (PAUSED.equals(reason) || DO_NOT_DISTURB.equals(reason));
  }

  /** The event in {@code payload}, or null for one that is not a JSON object with a type. */
  public static SleeveEvent parse(String payload) {
    Object document;
    try {
      document = PyJson.loads(payload);
    } catch (JsonDecodeException | NonFiniteLiteralException error) {
      return null;
    }
    if (!(document instanceof Map<?, ?> map) || !(map.get("type") instanceof String type)) {
      return null;
    }
    @SuppressWarnings("unchecked")
    Map<String, Object> fields = (Map<String, Object>) map;
    Object seq = fields.get("seq");
    // 3.0 is 3 (JavaScript cannot tell them apart); anything else is no seq.
    Long seqValue = null;
    if (seq instanceof Long l) {
      seqValue = l;
    } else if (seq instanceof Double d && d == Math.rint(d) && Math.abs(d) <= 9.007199254740991E15) {
      seqValue = (long) (double) d;
    }
    return new SleeveEvent(
        type,
        fields.get("drawing") instanceof String s ? s : null,
        seqValue,
        fields.get("reason") instanceof String s ? s : null,
        fields.get("message") instanceof String s ? s : null,
        fields);
  }
}
