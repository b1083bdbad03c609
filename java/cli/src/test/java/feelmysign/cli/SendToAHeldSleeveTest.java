package feelmysign.cli;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.mqtt3.Mqtt3BlockingClient;
import com.hivemq.client.mqtt.mqtt3.message.publish.Mqtt3Publish;
import feelmysign.testing.LiveSleeve;
import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.PrintStream;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.time.Instant;
import java.time.ZoneId;
import java.time.format.DateTimeFormatter;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;

/**
 * feelmysign-java send to a sleeve whose wearer paused it, or asked not to be disturbed: nothing
 * is sent, one line says so in the Python CLI's words, exit 3; a sleeve not held gets the
 * drawing. A real Mosquitto ({@code feelmysign broker}); the sleeve's retained status is published
 * with the sleeve's own account, and a client logged in as the sleeve counts what arrives.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class SendToAHeldSleeveTest {
  private static final String SLEEVE = "held-sleeve";
  private static final String NONE =
      "{\"paused\": false, \"paused_by\": null, \"ceiling\": null, \"do_not_disturb_until_ms\": null}";
  private LiveSleeve live;
  private Mqtt3BlockingClient sleeve;
  private Mqtt3BlockingClient.Mqtt3Publishes strokes;

  private record Result(int code, String out, String err) {}

  @BeforeAll
  void start(@TempDir Path state) throws IOException {
    live = LiveSleeve.brokerOnly(state, SLEEVE);
    URI url = URI.create(live.mqttUrl());
    sleeve = MqttClient.builder().useMqttVersion3().identifier("held-sleeve-test")
        .serverHost(url.getHost()).serverPort(url.getPort()).buildBlocking();
    sleeve.connectWith().simpleAuth().username(live.sleeveUser())
        .password(live.sleevePassword().getBytes(StandardCharsets.UTF_8)).applySimpleAuth().send();
    strokes = sleeve.publishes(com.hivemq.client.mqtt.MqttGlobalPublishFilter.ALL);
    sleeve.subscribeWith().topicFilter("feelmysign/" + SLEEVE + "/strokes")
        .qos(MqttQos.AT_LEAST_ONCE).send();
  }

  @AfterAll
  void stop() throws InterruptedException {
    if (sleeve != null) {
      sleeve.disconnect();
    }
    if (live != null) {
      live.close();
    }
  }

  private void status(String controls) {
    String status = "{\"online\": true, \"sleeve_id\": \"" + SLEEVE + "\", \"layout\": {\"rows\": 3,"
        + " \"columns\": 4}, \"controls\": " + controls + "}";
    sleeve.publishWith().topic("feelmysign/" + SLEEVE + "/status").qos(MqttQos.AT_LEAST_ONCE)
        .retain(true).payload(status.getBytes(StandardCharsets.UTF_8)).send();
  }

  private Result send() {
    ByteArrayOutputStream out = new ByteArrayOutputStream();
    ByteArrayOutputStream err = new ByteArrayOutputStream();
    int code = Main.run(new String[] {"send", "--credentials", live.credentials().toString(),
        "--id", SLEEVE, "--timeout-s", "60", "0,0,2,0,300", "2,0,2,2,300"},
        new PrintStream(out, true, StandardCharsets.UTF_8),
        new PrintStream(err, true, StandardCharsets.UTF_8));
    return new Result(code, out.toString(StandardCharsets.UTF_8), err.toString(StandardCharsets.UTF_8));
  }

  private Mqtt3Publish received(long waitMs) throws InterruptedException {
    return strokes.receive(waitMs, TimeUnit.MILLISECONDS).orElse(null);
  }

  @Test
  void aPausedSleeveGetsNothingAndTheSenderIsToldWhy() throws InterruptedException {
    status("{\"paused\": true, \"paused_by\": \"button\", \"ceiling\": null,"
        + " \"do_not_disturb_until_ms\": null}");
    Result paused = send();
    assertEquals(3, paused.code(), paused.err());
    assertEquals("Error: The wearer paused sleeve '" + SLEEVE + "': it plays nothing and refuses"
        + " every stroke until the wearer resumes it (their button or the wearer's page). Nothing"
        + " was sent; send again once the wearer has resumed.\n", paused.err().replace("\r\n", "\n"));
    assertNull(received(500), "a stroke reached a paused sleeve");

    long untilMs = System.currentTimeMillis() + 20 * 60_000;
    status("{\"paused\": false, \"paused_by\": null, \"ceiling\": null,"
        + " \"do_not_disturb_until_ms\": " + untilMs + "}");
    Result quiet = send();
    assertEquals(3, quiet.code(), quiet.err());
    String until = DateTimeFormatter.ofPattern("HH:mm")
        .format(Instant.ofEpochMilli(untilMs).atZone(ZoneId.systemDefault()));
    assertTrue(quiet.err().startsWith("Error: The wearer of sleeve '" + SLEEVE
        + "' asked not to be disturbed until " + until + ": it refuses every stroke until then."),
        quiet.err());
    assertNull(received(500), "a stroke reached a sleeve in do not disturb");

    // Resumed: the drawing goes out.
    status(NONE);
    Result resumed = send();
    assertEquals(0, resumed.code(), resumed.err());
    assertTrue(received(10_000) != null && received(10_000) != null, "both strokes sent");
  }
}
