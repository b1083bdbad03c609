package feelmysign.protocol;

import java.util.LinkedHashMap;
import java.util.Map;

/** The reason codes of refused messages: stable, snake_case, the same in every language. */
public final class Reasons {
  private Reasons() {}

  public static final String NOT_TEXT = "not_text";
  public static final String TOO_LONG = "too_long";
  public static final String EMPTY = "empty";
  public static final String WRONG_FIELD_COUNT = "wrong_field_count";
  public static final String NOT_A_NUMBER = "not_a_number";
  public static final String NOT_FINITE = "not_finite";
  public static final String INVALID_JSON = "invalid_json";
  public static final String NOT_AN_OBJECT = "not_an_object";
  public static final String MISSING_FIELD = "missing_field";
  public static final String WRONG_TYPE = "wrong_type";
  public static final String UNKNOWN_VERSION = "unknown_version";
  public static final String BAD_DRAWING_ID = "bad_drawing_id";
  public static final String SEQ_OUT_OF_RANGE = "seq_out_of_range";
  public static final String OUTSIDE_GRID = "outside_grid";
  public static final String DURATION_NOT_POSITIVE = "duration_not_positive";
  public static final String DURATION_TOO_LONG = "duration_too_long";
  public static final String INTENSITY_OUT_OF_RANGE = "intensity_out_of_range";
  public static final String SENT_AT_OUT_OF_RANGE = "sent_at_out_of_range";

  /** Every reason and what it means (docs/protocol.md). */
  public static final Map<String, String> ALL;

  static {
    Map<String, String> all = new LinkedHashMap<>();
    all.put(NOT_TEXT, "the payload is not a string or bytes, or its bytes are not UTF-8");
    all.put(TOO_LONG, "the payload is longer than " + Protocol.MAX_PAYLOAD_BYTES + " bytes (UTF-8)");
    all.put(EMPTY, "the payload is empty or only whitespace");
    all.put(WRONG_FIELD_COUNT, "a legacy payload without exactly 5 comma-separated fields");
    all.put(NOT_A_NUMBER, "a legacy field that is not a decimal number");
    all.put(NOT_FINITE, "a number that is NaN, infinite or too large to represent");
    all.put(INVALID_JSON, "a payload chosen as JSON that is not valid JSON");
    all.put(NOT_AN_OBJECT, "valid JSON that is not an object");
    all.put(
        MISSING_FIELD, "a JSON message without a required field (v, start, end, duration_ms)");
    all.put(
        WRONG_TYPE,
        "a JSON field of the wrong type (e.g. start not [x, y], seq not an integer)");
    all.put(UNKNOWN_VERSION, "a JSON message whose v is not " + Protocol.JSON_VERSION);
    all.put(
        BAD_DRAWING_ID,
        "drawing is not 1 to 64 printable ASCII characters without spaces");
    all.put(SEQ_OUT_OF_RANGE, "seq is below 0 or above " + Protocol.MAX_SEQ);
    all.put(OUTSIDE_GRID, "start or end lies outside the sleeve's grid");
    all.put(DURATION_NOT_POSITIVE, "duration_ms is 0 or negative");
    all.put(DURATION_TOO_LONG, "duration_ms is above the sleeve's max_stroke_duration_ms");
    all.put(INTENSITY_OUT_OF_RANGE, "intensity is outside 0..1");
    all.put(SENT_AT_OUT_OF_RANGE, "sent_at_ms is negative or above 1e13 (the year 2286)");
    ALL = java.util.Collections.unmodifiableMap(all);
  }
}
