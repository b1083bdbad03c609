package feelmysign.protocol;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertInstanceOf;
import static org.junit.jupiter.api.Assertions.assertThrows;

import com.fasterxml.jackson.databind.JsonNode;
import feelmysign.VectorFiles;
import feelmysign.Vectors;
import feelmysign.protocol.ParseResult.Accepted;
import feelmysign.protocol.ParseResult.Rejected;
import java.util.Base64;
import java.util.stream.Stream;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.Arguments;
import org.junit.jupiter.params.provider.MethodSource;

/**
 * The Java protocol against every vector of testdata/protocol: accepted strokes, refusals
 * (reason, field and the reference's exact sentence) and the exact bytes of both formats.
 */
class ProtocolVectorsTest {
  private static Object payload(JsonNode vector) {
    String encoding = vector.get("payload_encoding").asText();
    JsonNode payload = vector.get("payload");
    return switch (encoding) {
      case "utf-8" -> payload.textValue();
      case "base64" -> Base64.getDecoder().decode(payload.textValue());
      case "json-value" -> Vectors.plain(payload);
      default -> throw new IllegalArgumentException("unknown payload_encoding " + encoding);
    };
  }

  private static ParseResult parse(JsonNode vector) {
    JsonNode layout = vector.get("layout");
    Layout limits =
        new Layout(
            layout.get("rows").asInt(),
            layout.get("columns").asInt(),
            layout.get("max_stroke_duration_ms").asDouble());
    Protocol.Format format =
        Protocol.Format.valueOf(vector.get("format").asText().toUpperCase(java.util.Locale.ROOT));
    return Protocol.parse(payload(vector), limits, format);
  }

  private static Stroke stroke(JsonNode s) {
    return new Stroke(
        s.get("start").get(0).doubleValue(),
        s.get("start").get(1).doubleValue(),
        s.get("end").get(0).doubleValue(),
        s.get("end").get(1).doubleValue(),
        s.get("duration_ms").doubleValue(),
        s.path("intensity").isNumber() ? s.get("intensity").doubleValue() : null,
        s.path("drawing").isTextual() ? s.get("drawing").textValue() : null,
        s.path("seq").isNumber() ? s.get("seq").longValue() : null,
        s.path("sent_at_ms").isNumber() ? s.get("sent_at_ms").doubleValue() : null);
  }

  @ParameterizedTest(name = "{0}")
  @VectorFiles("protocol/valid")
  void acceptsAsTheReference(String name, JsonNode vector) {
    JsonNode expected = vector.get("expected");
    Accepted accepted = assertInstanceOf(Accepted.class, parse(vector), name);
    assertEquals(expected.get("format").asText(), accepted.format().wireName());
    assertEquals(stroke(expected.get("stroke")), accepted.stroke());
  }

  @ParameterizedTest(name = "{0}")
  @VectorFiles("protocol/invalid")
  void refusesAsTheReference(String name, JsonNode vector) {
    JsonNode expected = vector.get("expected");
    Rejected rejected = assertInstanceOf(Rejected.class, parse(vector), name);
    assertEquals(expected.get("reason").asText(), rejected.reason(), "reason");
    assertEquals(
        expected.get("field").isNull() ? null : expected.get("field").asText(),
        rejected.field(),
        "field");
    assertEquals(expected.get("message").asText(), rejected.message(), "message");
  }

  @ParameterizedTest(name = "{0}")
  @VectorFiles("protocol/format")
  void formatsTheSameBytes(String name, JsonNode vector) {
    Stroke stroke = stroke(vector.get("stroke"));
    assertEquals(vector.get("json").asText(), Protocol.formatJson(stroke));
    assertEquals(vector.get("legacy").asText(), Protocol.formatLegacy(stroke));
  }

  @ParameterizedTest(name = "{0}")
  @MethodSource("invalidStrokes")
  void refusesInvalidStrokesBeforeTheWire(String reason, Stroke stroke) {
    assertEquals(reason, Protocol.strokeProblem(stroke).reason());
    StrokeException json = assertThrows(StrokeException.class, () -> Protocol.formatJson(stroke));
    assertEquals(reason, json.reason());
    assertThrows(StrokeException.class, () -> Protocol.formatLegacy(stroke));
  }

  static Stream<Arguments> invalidStrokes() {
    return Stream.of(
        Arguments.of("duration_not_positive", new Stroke(0, 0, 1, 1, 0)),
        Arguments.of("not_finite", new Stroke(Double.NaN, 0, 1, 1, 100)),
        Arguments.of(
            "intensity_out_of_range", new Stroke(0, 0, 1, 1, 100, 1.5, null, null, null)),
        Arguments.of("seq_out_of_range", new Stroke(0, 0, 1, 1, 100, null, null, -1L, null)),
        Arguments.of("bad_drawing_id", new Stroke(0, 0, 1, 1, 100, null, "a b", null, null)),
        Arguments.of("sent_at_out_of_range", new Stroke(0, 0, 1, 1, 100, null, null, null, -5.0)));
  }
}
