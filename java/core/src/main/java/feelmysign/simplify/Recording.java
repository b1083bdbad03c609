package feelmysign.simplify;

import feelmysign.json.JsonDecodeException;
import feelmysign.json.JsonKind;
import feelmysign.json.Numbers;
import feelmysign.json.NonFiniteLiteralException;
import feelmysign.json.PyJson;
import feelmysign.json.PyRepr;
import java.math.BigInteger;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Map;

/**
 * A recording: the pointer samples of a drawing, as JSON, for exact replay (the reference's
 * {@code simplify/recording.py}; the format is in docs/research.md). Read with the same checks
 * and the same messages.
 *
 * <pre>
 * {"canvas": {"width_px": W, "height_px": H},
 *  "paths": [[{"t_ms": t, "x": x, "y": y, "pressure": p}, ...], ...],
 *  "sleeve": {"rows": R, "columns": C},                  optional
 *  "simplifier": {"algorithm": "angle", "params": {}},   optional: what the sender used
 *  "frames": [...], "strokes": [...]}                    optional: what the sender fed and sent
 * </pre>
 */
public record Recording(
    double widthPx,
    double heightPx,
    List<List<Sample>> paths,
    Integer rows,
    Integer columns,
    Map<String, Object> simplifier) {

  /**
   * A recording file's bytes as text: UTF-8, or a RecordingException naming the offset of the
   * first byte that is not (as the reference's {@code load_recording} says it).
   */
  public static String decode(byte[] data, String source) {
    var decoder = java.nio.charset.StandardCharsets.UTF_8.newDecoder()
        .onMalformedInput(java.nio.charset.CodingErrorAction.REPORT)
        .onUnmappableCharacter(java.nio.charset.CodingErrorAction.REPORT);
    java.nio.ByteBuffer in = java.nio.ByteBuffer.wrap(data);
    java.nio.CharBuffer out = java.nio.CharBuffer.allocate(data.length);
    java.nio.charset.CoderResult result = decoder.decode(in, out, true);
    if (!result.isError()) {
      result = decoder.flush(out);
    }
    if (result.isError()) {
      // The decoder stops at the first byte of the malformed sequence, as Python's start.
      throw new RecordingException(source + ": not UTF-8 text (byte " + in.position()
          + "); a recording is JSON saved as UTF-8");
    }
    return out.flip().toString();
  }

  /** Read a recording's text; {@code source} names it in messages. */
  public static Recording parse(String text, String source) {
    Object data;
    try {
      data = PyJson.loads(text);
    } catch (NonFiniteLiteralException error) {
      throw new RecordingException(
          source + ": not valid JSON (" + error.literal() + " is not a number)");
    } catch (JsonDecodeException error) {
      if (text.stripLeading().startsWith("<")) {
        throw new RecordingException(
            source
                + ": XML, not a recording; simplify and replay read recording JSON (the page's"
                + " Save), and feelmysign evaluate reads $1 gesture logs (.xml)");
      }
      String detail = error.tooDeep() ? "nested too deeply to read" : error.getMessage();
      throw new RecordingException(source + ": not valid JSON (" + detail + ")");
    }
    if (!(data instanceof Map<?, ?> object)) {
      throw new RecordingException(
          source + ": the recording must be a JSON object with canvas and paths");
    }
    Map<?, ?> canvas = (Map<?, ?>) field(object, "canvas", true, source);
    double width = positive(canvas, "width_px", source);
    double height = positive(canvas, "height_px", source);
    List<?> rawPaths = (List<?>) field(object, "paths", false, source);
    List<List<Sample>> paths = new ArrayList<>();
    for (int i = 0; i < rawPaths.size(); i++) {
      paths.add(path(rawPaths.get(i), i, source, "paths"));
    }
    Object sleeve = orEmpty(object.get("sleeve"));
    Object simplifier = orEmpty(object.get("simplifier"));
    if (!(sleeve instanceof Map<?, ?> sleeveMap) || !(simplifier instanceof Map<?, ?>)) {
      throw new RecordingException(
          source + ": sleeve and simplifier, when given, must be objects");
    }
    if (object.get("frames") != null) {
      List<?> rawFrames = (List<?>) field(object, "frames", false, source);
      for (int i = 0; i < rawFrames.size(); i++) {
        path(rawFrames.get(i), i, source, "frames");
      }
    }
    if (object.get("strokes") != null) {
      List<?> rawStrokes = (List<?>) field(object, "strokes", false, source);
      for (int i = 0; i < rawStrokes.size(); i++) {
        stroke(rawStrokes.get(i), i, source);
      }
    }
    @SuppressWarnings("unchecked")
    Map<String, Object> settings = (Map<String, Object>) simplifier;
    return new Recording(
        width,
        height,
        Collections.unmodifiableList(paths),
        gridSide(sleeveMap.get("rows"), "rows", source),
        gridSide(sleeveMap.get("columns"), "columns", source),
        settings);
  }

  /** Python's {@code x or {}}: null, false, 0, "", [] and {} are all "not given". */
  private static Object orEmpty(Object value) {
    boolean falsy =
        value == null
            || Boolean.FALSE.equals(value)
            || (value instanceof Long l && l == 0)
            || (value instanceof Double d && d == 0)
            || (value instanceof String s && s.isEmpty())
            || (value instanceof List<?> list && list.isEmpty())
            || (value instanceof Map<?, ?> map && map.isEmpty());
    return falsy ? Map.of() : value;
  }

  private static Object field(Map<?, ?> data, String key, boolean object, String source) {
    Object value = data.get(key);
    if (object ? !(value instanceof Map) : !(value instanceof List)) {
      String wanted = object ? "an object" : "an array";
      String found = data.containsKey(key) ? "is " + JsonKind.of(value) : "is missing";
      throw new RecordingException(
          source
              + ": '"
              + key
              + "' must be "
              + wanted
              + " but "
              + found
              + "; a recording is the JSON file the drawing page's Save button downloads"
              + " (its format: docs/research.md, Recordings)");
    }
    return value;
  }

  private static double positive(Map<?, ?> data, String key, String source) {
    Object value = data.get(key);
    if (!isNumber(value) || toDouble(value) <= 0) {
      throw new RecordingException(
          source + ": canvas." + key + " must be a number > 0, got " + PyRepr.of(value));
    }
    return toDouble(value);
  }

  private static List<Sample> path(Object raw, int index, String source, String key) {
    if (!(raw instanceof List<?> items) || items.isEmpty()) {
      throw new RecordingException(
          source + ": " + key + "[" + index + "] must be a non-empty list of samples");
    }
    List<Sample> samples = new ArrayList<>(items.size());
    for (int k = 0; k < items.size(); k++) {
      String where = source + ": " + key + "[" + index + "][" + k + "]";
      if (!(items.get(k) instanceof Map<?, ?> item)) {
        throw new RecordingException(where + " must be an object with t_ms, x, y");
      }
      Object t = item.get("t_ms");
      Object x = item.get("x");
      Object y = item.get("y");
      if (!isNumber(t) || !isNumber(x) || !isNumber(y)) {
        throw new RecordingException(
            where + " needs finite numbers t_ms, x, y; got " + PyRepr.of(item));
      }
      Object pressure = item.containsKey("pressure") ? item.get("pressure") : (Object) 0.5;
      if (!isNumber(pressure) || !(0 <= toDouble(pressure) && toDouble(pressure) <= 1)) {
        throw new RecordingException(
            where + ": pressure must be in [0, 1], got " + PyRepr.of(pressure));
      }
      double tMs = toDouble(t);
      if (!samples.isEmpty() && tMs < samples.get(samples.size() - 1).tMs()) {
        throw new RecordingException(
            where
                + ": t_ms "
                + Numbers.pythonG(tMs)
                + " goes back in time (samples must be in order)");
      }
      samples.add(new Sample(tMs, toDouble(x), toDouble(y), toDouble(pressure)));
    }
    return Collections.unmodifiableList(samples);
  }

  private static void stroke(Object raw, int index, String source) {
    String where = source + ": strokes[" + index + "]";
    if (!(raw instanceof Map<?, ?> item)) {
      throw new RecordingException(
          where + " must be an object with path, start, end, start_ms, end_ms");
    }
    Object path = item.get("path");
    boolean pathOk =
        (path instanceof Long l && l >= 0) || (path instanceof BigInteger b && b.signum() >= 0);
    if (!pathOk) {
      throw new RecordingException(
          where + ": path must be a path index (0 or more), got " + PyRepr.of(path));
    }
    if (!isNumber(item.get("start_ms")) || !isNumber(item.get("end_ms"))) {
      throw new RecordingException(
          where + " needs finite numbers start_ms, end_ms; got " + PyRepr.of(item));
    }
    for (String key : new String[] {"start", "end"}) {
      Object value = item.get(key);
      if (!(value instanceof List<?> point
          && point.size() == 2
          && isNumber(point.get(0))
          && isNumber(point.get(1)))) {
        throw new RecordingException(
            where + ": start and end must be [x, y] numbers, got " + PyRepr.of(value));
      }
    }
  }

  /** A finite JSON number, not a boolean (as the reference's _is_number). */
  static boolean isNumber(Object value) {
    if (value instanceof Long) {
      return true;
    }
    if (value instanceof BigInteger big) {
      return Double.isFinite(big.doubleValue());
    }
    return value instanceof Double d && Double.isFinite(d);
  }

  static double toDouble(Object value) {
    if (value instanceof BigInteger big) {
      return big.doubleValue();
    }
    return ((Number) value).doubleValue();
  }

  /** sleeve.rows or sleeve.columns: absent, or a whole number from 1 to 64, as in a layout. */
  private static Integer gridSide(Object value, String key, String source) {
    if (value == null) {
      return null;
    }
    if (!(value instanceof Long l) || l < 1 || l > 64) {
      throw new RecordingException(
          source
              + ": sleeve."
              + key
              + " must be a whole number from 1 to 64, got "
              + PyRepr.of(value)
              + "; fix it or remove it (then --"
              + key
              + " or the default applies)");
    }
    return (int) (long) l;
  }
}
