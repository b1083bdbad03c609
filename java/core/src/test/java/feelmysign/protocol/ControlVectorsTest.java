package feelmysign.protocol;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.fasterxml.jackson.databind.JsonNode;
import feelmysign.VectorFiles;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.params.ParameterizedTest;

/** The control (cancel) message against testdata/control, and the topics. */
class ControlVectorsTest {
  @ParameterizedTest(name = "{0}")
  @VectorFiles("control/valid")
  void reads(String name, JsonNode vector) {
    Control.Result result = Control.parseControl(vector.get("payload").textValue());
    assertNull(result.rejected(), name);
    assertEquals(vector.get("cancel").asText(), result.cancel().drawing());
  }

  @ParameterizedTest(name = "{0}")
  @VectorFiles("control/invalid")
  void refuses(String name, JsonNode vector) {
    Control.Result result = Control.parseControl(vector.get("payload").textValue());
    assertNotNull(result.rejected(), name);
    assertEquals(vector.get("reason").asText(), result.rejected().reason());
    assertEquals(
        vector.get("field").isNull() ? null : vector.get("field").asText(),
        result.rejected().field());
    assertEquals(vector.get("message").asText(), result.rejected().message());
  }

  @ParameterizedTest(name = "{0}")
  @VectorFiles("control/format")
  void formats(String name, JsonNode vector) {
    Control.Cancel cancel = new Control.Cancel(vector.get("cancel").asText());
    assertEquals(vector.get("text").asText(), Control.formatControl(cancel));
  }

  @Test
  void cancelMatchesItsDrawingOrEverything() {
    assertTrue(new Control.Cancel("*").matches(null));
    assertTrue(new Control.Cancel("d1").matches("d1"));
    assertEquals(false, new Control.Cancel("d1").matches("d2"));
    assertThrows(
        IllegalArgumentException.class, () -> Control.formatControl(new Control.Cancel("a b")));
  }

  @Test
  void topicsFollowTheReferenceRules() {
    assertEquals("feelmysign/s1/strokes", Topics.strokesTopic("s1"));
    assertEquals("feelmysign/s1/control", Topics.controlTopic("s1"));
    assertEquals("feelmysign/+/events", Topics.telemetryTopic(Topics.ANY_SLEEVE, "events"));
    assertEquals("deviceOne/line", Topics.LEGACY_TOPIC);
    assertThrows(IllegalArgumentException.class, () -> Topics.telemetryTopic("s1", "strokes"));
  }
}
