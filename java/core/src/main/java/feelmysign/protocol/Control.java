package feelmysign.protocol;

import static feelmysign.protocol.Reasons.*;

import feelmysign.json.JsonDecodeException;
import feelmysign.json.NonFiniteLiteralException;
import feelmysign.json.PyDumps;
import feelmysign.json.PyJson;
import feelmysign.protocol.ParseResult.Rejected;
import java.math.BigInteger;
import java.util.List;
import java.util.Map;

/**
 * The control message: a sender tells the sleeve to cancel one drawing, or everything (a port
 * of {@code control.py}). Published (QoS 1, never retained) on {@code feelmysign/<id>/control}:
 *
 * <pre>
 * {"v":1,"cancel":"6f1c2a9e-3b7d-4c55-9a1e-2f0b8d4c7e31"}   one drawing
 * {"v":1,"cancel":"*"}                                       everything
 * </pre>
 *
 * Checked like a stroke: the same payload limits and reason codes, and the same vectors for every
 * port ({@code testdata/control}).
 */
public final class Control {
  private Control() {}

  public static final String CANCEL_ALL = "*";
  private static final String EXAMPLE = "{\"v\":1,\"cancel\":\"*\"}";

  /** Cancel the strokes of {@code drawing}, or of every drawing when it is {@code "*"}. */
  public record Cancel(String drawing) {
    public boolean everything() {
      return CANCEL_ALL.equals(drawing);
    }

    /** Whether a stroke of {@code strokeDrawing} (null: a stroke without one) is cancelled. */
    public boolean matches(String strokeDrawing) {
      return everything() || drawing.equals(strokeDrawing);
    }
  }

  /** What {@link #parseControl} makes of a payload: a {@link Cancel} or a {@link Rejected}. */
  public record Result(Cancel cancel, Rejected rejected) {}

  /** The exact text senders publish: compact, keys {@code v, cancel}. */
  public static String formatControl(Cancel cancel) {
    if (!cancel.everything() && !Protocol.isDrawingId(cancel.drawing())) {
      throw new IllegalArgumentException(
          "not a drawing id: " + PyDumps.dumps(String.valueOf(cancel.drawing())));
    }
    return "{\"v\":" + Protocol.JSON_VERSION + ",\"cancel\":" + PyDumps.dumps(cancel.drawing()) + "}";
  }

  /** Read one control message; never throws. Unknown keys are ignored, as in strokes. */
  public static Result parseControl(Object payload) {
    Object text = Protocol.payloadText(payload, EXAMPLE);
    if (text instanceof Rejected rejected) {
      return new Result(null, rejected);
    }
    String body = Protocol.strip((String) text);
    if (body.isEmpty()) {
      return rejected(EMPTY, "The control message is empty; send e.g. " + EXAMPLE + ".", null);
    }
    Object document;
    try {
      document = PyJson.loads(body);
    } catch (NonFiniteLiteralException | JsonDecodeException error) {
      return rejected(
          INVALID_JSON, "The control message is not valid JSON; send e.g. " + EXAMPLE + ".", null);
    }
    if (!(document instanceof Map<?, ?> object)) {
      return rejected(
          NOT_AN_OBJECT, "The control message must be a JSON object such as " + EXAMPLE + ".", null);
    }
    for (String key : new String[] {"v", "cancel"}) {
      if (object.get(key) == null) {
        return rejected(
            MISSING_FIELD,
            "The control message has no \""
                + key
                + "\"; it needs v and cancel, e.g. "
                + EXAMPLE
                + ".",
            key);
      }
    }
    Object version = object.get("v");
    if (!(version instanceof Long || version instanceof BigInteger || version instanceof Double)) {
      return rejected(WRONG_TYPE, "\"v\" must be the number " + Protocol.JSON_VERSION + ".", "v");
    }
    double asDouble =
        version instanceof Double d
            ? d
            : version instanceof Long l ? l.doubleValue() : ((BigInteger) version).doubleValue();
    if (asDouble != Protocol.JSON_VERSION) {
      return rejected(
          UNKNOWN_VERSION,
          "\"v\" is "
              + Text.pythonStr(version)
              + "; this sleeve understands only version "
              + Protocol.JSON_VERSION
              + ".",
          "v");
    }
    Object drawing = object.get("cancel");
    if (!(drawing instanceof String id)) {
      return rejected(
          WRONG_TYPE, "\"cancel\" must be a string: a drawing id, or \"*\" for everything.", "cancel");
    }
    if (!id.equals(CANCEL_ALL) && !Protocol.isDrawingId(id)) {
      return rejected(
          BAD_DRAWING_ID,
          "\"cancel\" must be \"*\" or a drawing id of 1 to "
              + Protocol.MAX_DRAWING_ID_CHARS
              + " printable ASCII characters without spaces.",
          "cancel");
    }
    return new Result(new Cancel(id), null);
  }

  private static Result rejected(String reason, String message, String field) {
    return new Result(null, new Rejected(reason, message, field));
  }
}
