package feelmysign.protocol;

import static feelmysign.protocol.Reasons.*;

import feelmysign.json.JsonDecodeException;
import feelmysign.json.NonFiniteLiteralException;
import feelmysign.json.Numbers;
import feelmysign.json.PyDumps;
import feelmysign.json.PyRepr;
import feelmysign.json.PyJson;
import feelmysign.protocol.ParseResult.Accepted;
import feelmysign.protocol.ParseResult.Rejected;
import java.math.BigDecimal;
import java.math.BigInteger;
import java.math.RoundingMode;
import java.nio.ByteBuffer;
import java.nio.CharBuffer;
import java.nio.charset.CharsetDecoder;
import java.nio.charset.CodingErrorAction;
import java.nio.charset.StandardCharsets;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.regex.Pattern;

/**
 * Stroke messages on the wire: the original sleeve's legacy CSV and JSON v1, a port of the
 * Python reference {@code feelmysign/protocol.py} held to the shared vectors in
 * {@code testdata/protocol/}.
 *
 * <p>{@link #parse} turns a payload into an {@link Accepted} stroke or a {@link Rejected}
 * reason; it never throws, whatever the payload. {@link #formatLegacy} and {@link #formatJson}
 * write the text a sender publishes. Checks run in a fixed order and the first problem found is
 * reported, with the same reason code and sentence as the reference: payload (type, size,
 * UTF-8, empty), then the format's syntax, then the fields in wire order (drawing, seq, start,
 * end, duration_ms, intensity, sent_at_ms). docs/protocol.md describes both formats.
 */
public final class Protocol {
  private Protocol() {}

  /** One stroke fits in ~150 bytes; more is junk or an attack. */
  public static final int MAX_PAYLOAD_BYTES = 512;
  /** 1e-4 grid units is ~3 micrometres on a 3 cm grid: far below touch acuity. */
  public static final int LEGACY_DECIMALS = 4;
  /** A sender's float maths may land 2.9999999999 for 3; accepted, then clamped. */
  public static final double GRID_TOLERANCE = 1e-9;
  public static final int MAX_DRAWING_ID_CHARS = 64;
  /** The largest integer a JavaScript sender holds exactly. */
  public static final long MAX_SEQ = (1L << 53) - 1;

  /**
   * The latest {@code sent_at_ms} a sender's clock can give: 1e13 ms since 1970 is 20 November
   * 2286. Beyond it the clock is broken, and the stroke's pace would be nonsense.
   */
  public static final double MAX_SENT_AT_MS = 1e13;
  public static final int JSON_VERSION = 1;

  static final String LEGACY_EXAMPLE = "'0,0,2,0,1000'";
  static final String JSON_EXAMPLE = "{\"v\":1,\"start\":[0,0],\"end\":[2,0],\"duration_ms\":1000}";
  private static final String WHITESPACE = " \t\r\n";
  private static final String[] LEGACY_FIELDS = {"startX", "startY", "endX", "endY", "duration"};
  private static final String[] LEGACY_STROKE_FIELDS = {
    "start", "start", "end", "end", "duration_ms"
  };
  // ASCII only, as the reference: Java's and Python's number readers take more.
  private static final Pattern DECIMAL =
      Pattern.compile("[+-]?(?:[0-9]+(?:\\.[0-9]*)?|\\.[0-9]+)(?:[eE][+-]?[0-9]+)?");
  private static final Pattern NON_FINITE_WORD =
      Pattern.compile("[+-]?(?:nan|inf|infinity)", Pattern.CASE_INSENSITIVE);
  private static final Pattern DRAWING_ID = Pattern.compile("[!-~]{1," + MAX_DRAWING_ID_CHARS + "}");
  private static final BigInteger MAX_SEQ_BIG = BigInteger.valueOf(MAX_SEQ);

  /** How to read a payload: JSON when it starts with '{' or '[', else legacy ({@code AUTO}). */
  public enum Format {
    AUTO,
    LEGACY,
    JSON
  }

  /** {@link #parse(Object, Layout, Format)} with {@link Format#AUTO}. */
  public static ParseResult parse(Object payload, Layout layout) {
    return parse(payload, layout, Format.AUTO);
  }

  /**
   * Parse and validate one stroke message against {@code layout}'s grid and duration cap.
   *
   * @param payload the message: a {@code byte[]} (as MQTT delivers it) or a {@code String};
   *     anything else is refused as not text
   */
  public static ParseResult parse(Object payload, Layout layout, Format format) {
    Object text = payloadText(payload, LEGACY_EXAMPLE);
    if (text instanceof Rejected rejected) {
      return rejected;
    }
    String body = strip((String) text);
    if (body.isEmpty()) {
      return new Rejected(
          EMPTY,
          "The payload is empty; send a stroke such as "
              + LEGACY_EXAMPLE
              + " (startX,startY,endX,endY,duration in grid units and ms) or "
              + JSON_EXAMPLE
              + ".",
          null);
    }
    WireFormat chosen =
        switch (format) {
          case AUTO -> body.charAt(0) == '{' || body.charAt(0) == '['
              ? WireFormat.JSON
              : WireFormat.LEGACY;
          case LEGACY -> WireFormat.LEGACY;
          case JSON -> WireFormat.JSON;
        };
    Object stroke = chosen == WireFormat.JSON ? parseJson(body) : parseLegacy(body);
    if (stroke instanceof Rejected rejected) {
      return rejected;
    }
    Object checked = validate((Candidate) stroke, layout);
    if (checked instanceof Rejected rejected) {
      return rejected;
    }
    return new Accepted((Stroke) checked, chosen);
  }

  /**
   * Check {@code stroke} against {@code layout}: the stroke with its points clamped into the
   * grid, or why the sleeve would refuse it.
   */
  public static ParseResult validateStroke(Stroke stroke, Layout layout) {
    Object checked = validate(Candidate.of(stroke), layout);
    if (checked instanceof Rejected rejected) {
      return rejected;
    }
    return new Accepted((Stroke) checked, WireFormat.JSON);
  }

  /** The first problem of a stroke built in code (no grid), or null when it can be sent. */
  public static Rejected strokeProblem(Stroke stroke) {
    return firstProblem(Candidate.of(stroke), null);
  }

  /**
   * The legacy text {@code startX,startY,endX,endY,duration}: at most 4 decimals, no trailing
   * zeros. Rounds half away from zero on the exact binary value (what JavaScript's
   * {@code toFixed} does). Intensity, drawing, seq and sent_at_ms cannot be carried and are
   * dropped.
   *
   * @throws StrokeException for a stroke no sleeve would accept
   */
  public static String formatLegacy(Stroke stroke) {
    raiseIfInvalid(stroke);
    double[] numbers = {
      stroke.startX(), stroke.startY(), stroke.endX(), stroke.endY(), stroke.durationMs()
    };
    StringBuilder out = new StringBuilder();
    for (int i = 0; i < numbers.length; i++) {
      if (i > 0) {
        out.append(',');
      }
      out.append(legacyDecimal(numbers[i]));
    }
    return out.toString();
  }

  /**
   * The compact JSON v1 text, keys in wire order, optional fields left out when null. Numbers
   * are written as JavaScript's {@code JSON.stringify} writes them, so every port produces the
   * same bytes.
   *
   * @throws StrokeException for a stroke no sleeve would accept
   */
  public static String formatJson(Stroke stroke) {
    raiseIfInvalid(stroke);
    StringBuilder out = new StringBuilder("{\"v\":").append(JSON_VERSION);
    if (stroke.drawing() != null) {
      out.append(",\"drawing\":").append(PyDumps.dumps(stroke.drawing()));
    }
    if (stroke.seq() != null) {
      out.append(",\"seq\":").append(stroke.seq());
    }
    out.append(",\"start\":[")
        .append(Numbers.ecmascript(stroke.startX()))
        .append(',')
        .append(Numbers.ecmascript(stroke.startY()))
        .append("],\"end\":[")
        .append(Numbers.ecmascript(stroke.endX()))
        .append(',')
        .append(Numbers.ecmascript(stroke.endY()))
        .append("],\"duration_ms\":")
        .append(Numbers.ecmascript(stroke.durationMs()));
    if (stroke.intensity() != null) {
      out.append(",\"intensity\":").append(Numbers.ecmascript(stroke.intensity()));
    }
    if (stroke.sentAtMs() != null) {
      out.append(",\"sent_at_ms\":").append(Numbers.ecmascript(stroke.sentAtMs()));
    }
    return out.append('}').toString();
  }

  /** 1 to 64 printable ASCII characters without spaces (what {@code drawing} allows). */
  public static boolean isDrawingId(String text) {
    return text != null && DRAWING_ID.matcher(text).matches();
  }

  // --- payload ---------------------------------------------------------------------------

  /** The payload as text, or a Rejected (not_text / too_long); a byte-order mark dropped. */
  static Object payloadText(Object payload, String example) {
    byte[] data;
    String text = null;
    if (payload instanceof String s) {
      int lone = loneSurrogate(s);
      if (lone >= 0) {
        return new Rejected(
            NOT_TEXT,
            "The payload text cannot be encoded as UTF-8 (a lone surrogate at character "
                + lone
                + "); send valid Unicode text such as "
                + example
                + ".",
            null);
      }
      data = s.getBytes(StandardCharsets.UTF_8);
      text = s;
    } else if (payload instanceof byte[] bytes) {
      data = bytes;
    } else {
      String kind = payload == null ? "None" : "of type " + PyRepr.typeName(payload);
      return new Rejected(
          NOT_TEXT,
          "The payload is "
              + kind
              + ", not text; send a string or UTF-8 bytes such as "
              + example
              + ".",
          null);
    }
    if (data.length > MAX_PAYLOAD_BYTES) {
      return new Rejected(
          TOO_LONG,
          "The payload is "
              + data.length
              + " bytes long; the limit is "
              + MAX_PAYLOAD_BYTES
              + " bytes. Send one stroke per message.",
          null);
    }
    if (text == null) {
      CharsetDecoder decoder =
          StandardCharsets.UTF_8
              .newDecoder()
              .onMalformedInput(CodingErrorAction.REPORT)
              .onUnmappableCharacter(CodingErrorAction.REPORT);
      ByteBuffer in = ByteBuffer.wrap(data);
      CharBuffer out = CharBuffer.allocate(data.length + 1);
      var result = decoder.decode(in, out, true);
      if (!result.isError()) {
        result = decoder.flush(out);
      }
      if (result.isError()) {
        int at = in.position();
        return new Rejected(
            NOT_TEXT,
            String.format(
                "The payload is not UTF-8 text (byte 0x%02x at position %d); send ASCII such as "
                    + "%s or UTF-8 JSON.",
                data[at] & 0xff, at, example),
            null);
      }
      out.flip();
      text = out.toString();
    }
    // A byte-order mark is invisible in editors; TextDecoder drops it too.
    return text.startsWith("\ufeff") ? text.substring(1) : text;
  }

  /** The index (in code points) of the first lone surrogate, or -1. */
  private static int loneSurrogate(String s) {
    int codePoint = 0;
    for (int i = 0; i < s.length(); codePoint++) {
      char c = s.charAt(i);
      if (Character.isHighSurrogate(c)
          && i + 1 < s.length()
          && Character.isLowSurrogate(s.charAt(i + 1))) {
        i += 2;
        continue;
      }
      if (Character.isSurrogate(c)) {
        return codePoint;
      }
      i++;
    }
    return -1;
  }

  static String strip(String text) {
    int start = 0;
    int end = text.length();
    while (start < end && WHITESPACE.indexOf(text.charAt(start)) >= 0) {
      start++;
    }
    while (end > start && WHITESPACE.indexOf(text.charAt(end - 1)) >= 0) {
      end--;
    }
    return text.substring(start, end);
  }

  // --- legacy ----------------------------------------------------------------------------

  private static Object parseLegacy(String body) {
    String[] fields = body.split(",", -1);
    if (fields.length != LEGACY_FIELDS.length) {
      return new Rejected(WRONG_FIELD_COUNT, fieldCountMessage(body, fields.length), null);
    }
    double[] values = new double[5];
    for (int index = 0; index < fields.length; index++) {
      Object value = legacyNumber(strip(fields[index]), index);
      if (value instanceof Rejected rejected) {
        return rejected;
      }
      values[index] = (Double) value;
    }
    return new Candidate(values[0], values[1], values[2], values[3], values[4], null, null, null, null);
  }

  private static String fieldCountMessage(String body, int count) {
    String message =
        "The legacy payload "
            + Text.showText(body)
            + " has "
            + count
            + " comma-separated field(s); it needs exactly 5: startX,startY,endX,endY,duration "
            + "(e.g. "
            + LEGACY_EXAMPLE
            + ").";
    long commas = body.chars().filter(c -> c == ',').count();
    if (body.startsWith("{") || body.startsWith("[")) {
      message += " This looks like JSON: send it with the JSON format (or format auto).";
    } else if (count == 6) {
      message += " To send an intensity, use the JSON format.";
    } else if (count == 1 && (body.contains(";") || body.contains(" "))) {
      message += " Separate the fields with commas and use '.' as the decimal point.";
    } else if (count > 5 && commas >= 8) {
      message += " Use '.' as the decimal point, not ','.";
    }
    return message;
  }

  private static Object legacyNumber(String raw, int index) {
    String name = LEGACY_FIELDS[index];
    String field = LEGACY_STROKE_FIELDS[index];
    String where = "Field " + (index + 1) + " (" + name + ") of the legacy payload";
    if (NON_FINITE_WORD.matcher(raw).matches()) {
      return new Rejected(
          NOT_FINITE,
          where
              + " is "
              + Text.showText(raw)
              + ", which is not a finite number; "
              + "coordinates and the duration must be finite decimal numbers.",
          field);
    }
    if (!DECIMAL.matcher(raw).matches()) {
      String shown = raw.isEmpty() ? "empty" : Text.showText(raw);
      return new Rejected(
          NOT_A_NUMBER,
          where
              + " is "
              + shown
              + ", which is not a decimal number; write digits with '.' as the "
              + "decimal point, e.g. 420.5.",
          field);
    }
    double value = Double.parseDouble(raw);
    if (Double.isInfinite(value)) {
      return new Rejected(
          NOT_FINITE,
          where
              + " is "
              + Text.showText(raw)
              + ", which is too large to be a finite number; "
              + "coordinates are grid units and the duration milliseconds.",
          field);
    }
    return value;
  }

  // --- JSON ------------------------------------------------------------------------------

  private static Object parseJson(String body) {
    Object document;
    try {
      document = PyJson.loads(body);
    } catch (NonFiniteLiteralException error) {
      return new Rejected(
          INVALID_JSON,
          "The payload is not valid JSON: "
              + error.literal()
              + " is not a JSON number; send finite numbers only.",
          null);
    } catch (JsonDecodeException error) {
      return new Rejected(
          INVALID_JSON,
          "The payload is not valid JSON ("
              + jsonErrorText(error)
              + "); check quotes, commas and brackets, e.g. "
              + JSON_EXAMPLE
              + ".",
          null);
    }
    if (!(document instanceof Map<?, ?> object)) {
      return new Rejected(
          NOT_AN_OBJECT,
          "The JSON payload is "
              + Text.described(document)
              + ", not an object; send an object such as "
              + JSON_EXAMPLE
              + ".",
          null);
    }
    @SuppressWarnings("unchecked")
    Map<String, Object> fields = (Map<String, Object>) object;
    return strokeFromObject(fields);
  }

  private static String jsonErrorText(JsonDecodeException error) {
    if (error.tooDeep()) {
      return "nested too deeply";
    }
    // Some of Python's messages end in "at" already ("Invalid control character at").
    String what = error.msg();
    if (what.endsWith(" at")) {
      what = what.substring(0, what.length() - 3);
    }
    return what + " at line " + error.line() + ", column " + error.column();
  }

  /** Carries a Rejected out of the nested JSON readers; never escapes {@link #parse}. */
  private static final class Reject extends RuntimeException {
    private static final long serialVersionUID = 1L;
    final transient Rejected rejected;

    Reject(Rejected rejected) {
      super(rejected.message(), null, false, false);
      this.rejected = rejected;
    }
  }

  private static Object strokeFromObject(Map<String, Object> document) {
    if (!document.containsKey("v")) {
      return new Rejected(MISSING_FIELD, missingMessage("v", document), "v");
    }
    try {
      // The version before the other fields: another version may need other fields,
      // so "no start" would send its sender looking for the wrong problem.
      checkVersion(document.get("v"));
      for (String key : new String[] {"start", "end", "duration_ms"}) {
        if (!document.containsKey(key)) {
          return new Rejected(MISSING_FIELD, missingMessage(key, document), key);
        }
      }
      // Read in wire order, so the first problem reported is the same in every port.
      String drawing = readDrawing(document.get("drawing"));
      BigInteger seq = readSeq(document.get("seq"));
      double[] start = readPoint(document.get("start"), "start");
      double[] end = readPoint(document.get("end"), "end");
      double durationMs = readNumber(document.get("duration_ms"), "duration_ms");
      Double intensity = readOptionalNumber(document.get("intensity"), "intensity");
      Double sentAtMs = readOptionalNumber(document.get("sent_at_ms"), "sent_at_ms");
      return new Candidate(
          start[0], start[1], end[0], end[1], durationMs, intensity, drawing, seq, sentAtMs);
    } catch (Reject reject) {
      return reject.rejected;
    }
  }

  private static String missingMessage(String key, Map<String, Object> document) {
    String message =
        "The JSON message has no \""
            + key
            + "\"; the required fields are v, start, end and duration_ms, e.g. "
            + JSON_EXAMPLE
            + ".";
    // A typo or a unit left out ("duration" for "duration_ms") deserves a hint.
    List<String> others = new ArrayList<>();
    for (String k : document.keySet()) {
      if (!k.equals(key)) {
        others.add(k);
      }
    }
    String near = Text.closeMatch(key, others, 0.6);
    if (near != null) {
      message += " Found " + Text.showText(near) + ": did you mean \"" + key + "\"?";
    }
    return message;
  }

  private static void checkVersion(Object value) {
    if (!isNumber(value)) {
      throw wrongType("v", value, "the number " + JSON_VERSION);
    }
    if (toDouble(value) != JSON_VERSION) {
      throw new Reject(
          new Rejected(
              UNKNOWN_VERSION,
              "\"v\" is "
                  + Text.showJson(value)
                  + "; this sleeve understands only version "
                  + JSON_VERSION
                  + ". Send \"v\":"
                  + JSON_VERSION
                  + ", or update the sleeve.",
              "v"));
    }
  }

  private static String readDrawing(Object value) {
    if (value == null || value instanceof String) {
      return (String) value;
    }
    throw wrongType("drawing", value, "a string such as a UUID, or left out");
  }

  private static BigInteger readSeq(Object value) {
    if (value == null) {
      return null;
    }
    // 3.0 counts as an integer: JavaScript cannot tell 3.0 from 3.
    if (value instanceof Long l) {
      return BigInteger.valueOf(l);
    }
    if (value instanceof BigInteger big) {
      return big;
    }
    if (value instanceof Double d && Double.isFinite(d) && d == Math.rint(d)) {
      return new BigDecimal(d).toBigIntegerExact();
    }
    throw wrongType("seq", value, "a whole number from 0 to " + MAX_SEQ + ", or left out");
  }

  private static double[] readPoint(Object value, String key) {
    if (value instanceof List<?> list
        && list.size() == 2
        && isNumber(list.get(0))
        && isNumber(list.get(1))) {
      return new double[] {toDouble(list.get(0)), toDouble(list.get(1))};
    }
    throw wrongType(key, value, "an array of two numbers [x, y] in grid units");
  }

  private static double readNumber(Object value, String key) {
    if (isNumber(value)) {
      return toDouble(value);
    }
    throw wrongType(key, value, "a number");
  }

  private static Double readOptionalNumber(Object value, String key) {
    // null for an optional field means "not given", as if the key were absent.
    return value == null ? null : readNumber(value, key);
  }

  private static Reject wrongType(String key, Object value, String expected) {
    return new Reject(
        new Rejected(
            WRONG_TYPE,
            "\"" + key + "\" is " + Text.described(value) + "; it must be " + expected + ".",
            key));
  }

  private static boolean isNumber(Object value) {
    return value instanceof Long || value instanceof BigInteger || value instanceof Double;
  }

  /** A JSON number as a double; an integer too large for one is infinite, as in the reference. */
  private static double toDouble(Object value) {
    if (value instanceof Long l) {
      return l.doubleValue();
    }
    if (value instanceof BigInteger big) {
      return big.doubleValue();
    }
    return (Double) value;
  }

  // --- values ----------------------------------------------------------------------------

  /** A stroke as read, before validation: seq still a whole number of any size. */
  record Candidate(
      double startX,
      double startY,
      double endX,
      double endY,
      double durationMs,
      Double intensity,
      String drawing,
      BigInteger seq,
      Double sentAtMs) {
    static Candidate of(Stroke s) {
      return new Candidate(
          s.startX(),
          s.startY(),
          s.endX(),
          s.endY(),
          s.durationMs(),
          s.intensity(),
          s.drawing(),
          s.seq() == null ? null : BigInteger.valueOf(s.seq()),
          s.sentAtMs());
    }
  }

  private static Object validate(Candidate stroke, Layout layout) {
    Rejected problem = firstProblem(stroke, layout);
    if (problem != null) {
      return problem;
    }
    return new Stroke(
        clamp(stroke.startX(), layout.columns()),
        clamp(stroke.startY(), layout.rows()),
        clamp(stroke.endX(), layout.columns()),
        clamp(stroke.endY(), layout.rows()),
        stroke.durationMs(),
        stroke.intensity(),
        stroke.drawing(),
        stroke.seq() == null ? null : stroke.seq().longValueExact(),
        stroke.sentAtMs());
  }

  /** The first problem in wire order; grid and duration cap only checked with a layout. */
  private static Rejected firstProblem(Candidate stroke, Layout layout) {
    Rejected problem = checkDrawing(stroke.drawing());
    if (problem == null) {
      problem = checkSeq(stroke.seq());
    }
    if (problem == null) {
      problem = checkPoint(stroke.startX(), stroke.startY(), "start", layout);
    }
    if (problem == null) {
      problem = checkPoint(stroke.endX(), stroke.endY(), "end", layout);
    }
    if (problem == null) {
      problem = checkDuration(stroke.durationMs(), layout);
    }
    if (problem == null) {
      problem = checkIntensity(stroke.intensity());
    }
    if (problem == null) {
      problem = checkSentAt(stroke.sentAtMs());
    }
    return problem;
  }

  private static Rejected checkDrawing(String drawing) {
    if (drawing == null || DRAWING_ID.matcher(drawing).matches()) {
      return null;
    }
    return new Rejected(
        BAD_DRAWING_ID,
        "\"drawing\" is "
            + Text.showText(drawing)
            + " ("
            + drawing.codePointCount(0, drawing.length())
            + " characters); it must be 1 to "
            + MAX_DRAWING_ID_CHARS
            + " printable ASCII characters without spaces (a UUID works), or left out.",
        "drawing");
  }

  private static Rejected checkSeq(BigInteger seq) {
    if (seq == null || (seq.signum() >= 0 && seq.compareTo(MAX_SEQ_BIG) <= 0)) {
      return null;
    }
    return new Rejected(
        SEQ_OUT_OF_RANGE,
        "\"seq\" is "
            + Text.cut(seq.toString())
            + "; it must be a whole number from 0 to "
            + MAX_SEQ
            + " (count the strokes of a drawing from 0).",
        "seq");
  }

  private static Rejected checkPoint(double x, double y, String key, Layout layout) {
    if (!(Double.isFinite(x) && Double.isFinite(y))) {
      return new Rejected(
          NOT_FINITE,
          key
              + " ("
              + number(x)
              + ", "
              + number(y)
              + ") is not a finite point; coordinates must be finite numbers in grid units.",
          key);
    }
    if (layout == null || (inside(x, layout.columns()) && inside(y, layout.rows()))) {
      return null;
    }
    return new Rejected(
        OUTSIDE_GRID,
        key
            + " ("
            + number(x)
            + ", "
            + number(y)
            + ") is outside the "
            + layout.rows()
            + "-row x "
            + layout.columns()
            + "-column grid: x must be in 0.."
            + (layout.columns() - 1)
            + " and y in 0.."
            + (layout.rows() - 1)
            + " (grid units, counted from 0 at the first actuator); "
            + "scale the drawing to the sleeve's grid.",
        key);
  }

  private static boolean inside(double value, int count) {
    return -GRID_TOLERANCE <= value && value <= count - 1 + GRID_TOLERANCE;
  }

  private static Rejected checkDuration(double durationMs, Layout layout) {
    boolean capped = layout != null && durationMs > layout.maxStrokeDurationMs();
    if (Double.isFinite(durationMs) && durationMs > 0 && !capped) {
      return null;
    }
    String allowed = "more than 0 ms";
    if (layout != null) {
      allowed += " and at most " + number(layout.maxStrokeDurationMs()) + " ms";
    }
    if (!Double.isFinite(durationMs)) {
      return new Rejected(
          NOT_FINITE,
          "duration_ms is "
              + number(durationMs)
              + "; it must be a finite number of milliseconds, "
              + allowed
              + ".",
          "duration_ms");
    }
    if (durationMs <= 0) {
      return new Rejected(
          DURATION_NOT_POSITIVE,
          "duration_ms is " + number(durationMs) + "; a stroke must last " + allowed + ".",
          "duration_ms");
    }
    return new Rejected(
        DURATION_TOO_LONG,
        "duration_ms is "
            + number(durationMs)
            + "; this sleeve plays strokes of at most "
            + number(layout.maxStrokeDurationMs())
            + " ms. Split the stroke into shorter ones.",
        "duration_ms");
  }

  private static Rejected checkIntensity(Double intensity) {
    if (intensity == null) {
      return null;
    }
    if (!Double.isFinite(intensity)) {
      return new Rejected(
          NOT_FINITE,
          "intensity is " + number(intensity) + "; it must be a finite number from 0 to 1.",
          "intensity");
    }
    if (0 <= intensity && intensity <= 1) {
      return null;
    }
    return new Rejected(
        INTENSITY_OUT_OF_RANGE,
        "intensity is "
            + number(intensity)
            + "; it must be from 0 (off) to 1 (strongest), or left out for the sleeve's default.",
        "intensity");
  }

  private static Rejected checkSentAt(Double sentAtMs) {
    if (sentAtMs == null) {
      return null;
    }
    if (!Double.isFinite(sentAtMs)) {
      return new Rejected(
          NOT_FINITE,
          "sent_at_ms is " + number(sentAtMs) + "; it must be a finite time in milliseconds.",
          "sent_at_ms");
    }
    if (sentAtMs >= 0 && sentAtMs <= MAX_SENT_AT_MS) {
      return null;
    }
    if (sentAtMs > MAX_SENT_AT_MS) {
      return new Rejected(
          SENT_AT_OUT_OF_RANGE,
          "sent_at_ms is "
              + number(sentAtMs)
              + "; it must be the sender's clock in milliseconds since 1970-01-01 UTC, from 0 to "
              + number(MAX_SENT_AT_MS)
              + " (the year 2286): check the sender's clock, or leave it out.",
          "sent_at_ms");
    }
    return new Rejected(
        SENT_AT_OUT_OF_RANGE,
        "sent_at_ms is "
            + number(sentAtMs)
            + "; it must be the sender's clock in milliseconds since 1970-01-01 UTC (0 or more), "
            + "or left out.",
        "sent_at_ms");
  }

  private static double clamp(double value, int count) {
    // "+ 0.0" turns -0.0 into 0.0, so -0 never reaches a formatter.
    return Math.min(Math.max(value, 0.0), count - 1) + 0.0;
  }

  private static void raiseIfInvalid(Stroke stroke) {
    Rejected problem = firstProblem(Candidate.of(stroke), null);
    if (problem != null) {
      throw new StrokeException(problem.reason(), problem.message());
    }
  }

  // --- text ------------------------------------------------------------------------------

  static String legacyDecimal(double value) {
    String text =
        new BigDecimal(value).setScale(LEGACY_DECIMALS, RoundingMode.HALF_UP).toPlainString();
    if (text.contains(".")) {
      int end = text.length();
      while (text.charAt(end - 1) == '0') {
        end--;
      }
      if (text.charAt(end - 1) == '.') {
        end--;
      }
      text = text.substring(0, end);
    }
    return text.isEmpty() || text.equals("-0") ? "0" : text;
  }

  /** A number as ECMAScript's Number::toString writes it (messages quote numbers so). */
  static String number(double value) {
    return Numbers.ecmascript(value);
  }
}
