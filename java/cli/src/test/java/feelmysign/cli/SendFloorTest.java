package feelmysign.cli;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.MqttGlobalPublishFilter;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.mqtt3.Mqtt3BlockingClient;
import com.hivemq.client.mqtt.mqtt3.message.publish.Mqtt3Publish;
import feelmysign.protocol.Layout;
import feelmysign.protocol.ParseResult;
import feelmysign.protocol.Protocol;
import feelmysign.protocol.Stroke;
import feelmysign.testing.LiveSleeve;
import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.PrintStream;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;

/**
 * feelmysign-java send keeps to the floor the sleeve's retained status advertises: a recording is
 * cut keeping to it (with a wearer's limits, no stroke below them), and one line says the floor
 * and how many strokes are below it, as {@code feelmysign send} and {@code replay --send} say it.
 * A real Mosquitto ({@code feelmysign broker}); the status is published with the sleeve's own
 * account, and a client logged in as the sleeve reads the strokes that arrive.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class SendFloorTest {
  private static final String SLEEVE = "floor-sleeve";
  private LiveSleeve live;
  private Mqtt3BlockingClient sleeve;
  private Mqtt3BlockingClient.Mqtt3Publishes arriving;
  private Path recording;

  private record Result(int code, String out, String err) {}

  @BeforeAll
  void start(@TempDir Path state) throws IOException {
    live = LiveSleeve.brokerOnly(state, SLEEVE);
    URI url = URI.create(live.mqttUrl());
    sleeve = MqttClient.builder().useMqttVersion3().identifier("floor-sleeve-test")
        .serverHost(url.getHost()).serverPort(url.getPort()).buildBlocking();
    sleeve.connectWith().simpleAuth().username(live.sleeveUser())
        .password(live.sleevePassword().getBytes(StandardCharsets.UTF_8)).applySimpleAuth().send();
    arriving = sleeve.publishes(MqttGlobalPublishFilter.ALL);
    sleeve.subscribeWith().topicFilter("feelmysign/" + SLEEVE + "/strokes")
        .qos(MqttQos.AT_LEAST_ONCE).send();
    // A quick zigzag: ten legs of 0.46 grid units, 64 ms each, sharp turns between them.
    StringBuilder samples = new StringBuilder();
    int x = 200;
    int y = 300;
    long t = 0;
    samples.append("{\"t_ms\": 0, \"x\": ").append(x).append(", \"y\": ").append(y).append("}");
    for (int leg = 0; leg < 10; leg++) {
      int toX = x + 150;
      int toY = leg % 2 == 0 ? 550 : 300;
      for (int k = 1; k <= 4; k++) {
        t += 16;
        samples.append(", {\"t_ms\": ").append(t).append(", \"x\": ").append(x + (toX - x) * k / 4)
            .append(", \"y\": ").append(y + (toY - y) * k / 4).append("}");
      }
      x = toX;
      y = toY;
    }
    recording = state.resolve("zigzag.json");
    Files.writeString(recording, "{\"canvas\": {\"width_px\": 1920, \"height_px\": 1080},"
        + " \"sleeve\": {\"rows\": 3, \"columns\": 4}, \"paths\": [[" + samples + "]]}");
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

  private void status(String floor) {
    String status = "{\"online\": true, \"sleeve_id\": \"" + SLEEVE + "\", \"layout\": {\"rows\": 3,"
        + " \"columns\": 4}" + (floor == null ? "" : ", \"floor\": " + floor) + "}";
    sleeve.publishWith().topic("feelmysign/" + SLEEVE + "/status").qos(MqttQos.AT_LEAST_ONCE)
        .retain(true).payload(status.getBytes(StandardCharsets.UTF_8)).send();
  }

  private Result send(String... what) throws InterruptedException {
    // What an earlier test left unread is not this send's.
    while (arriving.receive(100, TimeUnit.MILLISECONDS).isPresent()) {
      continue;
    }
    List<String> args = new ArrayList<>(List.of("send", "--credentials",
        live.credentials().toString(), "--id", SLEEVE, "--timeout-s", "60", "--pace", "burst"));
    args.addAll(List.of(what));
    ByteArrayOutputStream out = new ByteArrayOutputStream();
    ByteArrayOutputStream err = new ByteArrayOutputStream();
    int code = Main.run(args.toArray(String[]::new),
        new PrintStream(out, true, StandardCharsets.UTF_8),
        new PrintStream(err, true, StandardCharsets.UTF_8));
    return new Result(code, out.toString(StandardCharsets.UTF_8),
        err.toString(StandardCharsets.UTF_8).replace("\r\n", "\n"));
  }

  /** The strokes that reached the sleeve's topic: {@code count} of them, then none more. */
  private List<Stroke> arrived(int count) throws InterruptedException {
    List<Stroke> strokes = new ArrayList<>();
    for (int i = 0; i < count; i++) {
      Optional<Mqtt3Publish> one = arriving.receive(LiveSleeve.WAIT_S, TimeUnit.SECONDS);
      assertTrue(one.isPresent(), "stroke " + (i + 1) + " of " + count + " did not arrive");
      String payload = new String(one.get().getPayloadAsBytes(), StandardCharsets.UTF_8);
      ParseResult parsed = Protocol.parse(payload, Layout.PAPER);
      assertTrue(parsed instanceof ParseResult.Accepted, payload);
      strokes.add(((ParseResult.Accepted) parsed).stroke());
    }
    assertTrue(arriving.receive(300, TimeUnit.MILLISECONDS).isEmpty(), "more strokes than sent");
    return strokes;
  }

  private static int count(Result sent) {
    java.util.regex.Matcher m =
        java.util.regex.Pattern.compile("^Sent (\\d+) stroke").matcher(sent.out());
    assertTrue(m.find(), sent.out());
    return Integer.parseInt(m.group(1));
  }

  private static boolean belowP01(Stroke s) {
    return s.durationMs() < 118.4
        || Math.hypot(s.endX() - s.startX(), s.endY() - s.startY()) < 0.62 - 1e-9;
  }

  @Test
  void aRecordingIsCutKeepingToAWearersFloorAndTheLineSaysSo() throws InterruptedException {
    // An older sleeve (no floor): the zigzag's legs go out as drawn, below P01's limits.
    status(null);
    Result plain = send("--recording", recording.toString());
    assertEquals(0, plain.code(), plain.err());
    assertEquals("", plain.err());
    List<Stroke> asDrawn = arrived(count(plain));
    assertTrue(asDrawn.stream().anyMatch(SendFloorTest::belowP01), asDrawn.toString());

    status("{\"min_duration_ms\": 118.4, \"min_length\": 0.62, \"wearer\": \"P01\"}");
    Result kept = send("--recording", recording.toString());
    assertEquals(0, kept.code(), kept.err());
    assertEquals("Raised min duration 118.4 ms and min length 0.62 grid units: the sleeve's floor"
        + " with wearer P01's limits.\n"
        + "The sleeve's floor with wearer P01's limits: strokes of at least 118.4 ms and 0.62"
        + " grid units; every stroke is at or above it.\n", kept.err());
    List<Stroke> strokes = arrived(count(kept));
    assertFalse(strokes.isEmpty());
    assertTrue(strokes.stream().noneMatch(SendFloorTest::belowP01), strokes.toString());
    // Strokes given below a wearer's limits go as given: the sleeve does not slow them to it.
    Result given = send("0,0,2,0,100", "2,0,2,2,300");
    assertEquals(0, given.code(), given.err());
    assertEquals("The sleeve's floor with wearer P01's limits: strokes of at least 118.4 ms and"
        + " 0.62 grid units; 1 of the 2 strokes are below it (sent as given: the wearer may not"
        + " feel a briefer or shorter one).\n", given.err());
    assertEquals(100.0, arrived(2).get(0).durationMs(), "sent as given");
  }

  @Test
  void strokesGoAsGivenAndTheLineCountsThoseBelowTheMotorsFloor() throws InterruptedException {
    status("{\"min_duration_ms\": 73.701, \"min_length\": 0.05}");
    Result some = send("0,0,2,0,50", "2,0,2,2,300");
    assertEquals(0, some.code(), some.err());
    assertEquals("The sleeve's floor: strokes of at least 73.701 ms and 0.05 grid units; 1 of the"
        + " 2 strokes are below it (the sleeve slows a briefer one; a shorter one may not be"
        + " felt).\n", some.err());
    assertEquals(50.0, arrived(2).get(0).durationMs(), "sent as given");
    Result none = send("0,0,2,0,300");
    assertEquals("", none.err(), "nothing below the motors' floor: nothing said");
    arrived(1);
    // A floor not understood: ignored, said once, and the strokes sent as given.
    status("{\"min_duration_ms\": -1, \"min_length\": 0.05}");
    Result bad = send("0,0,2,0,50");
    assertEquals(0, bad.code(), bad.err());
    assertEquals("The sleeve's floor in its status is not understood and was ignored"
        + " (min_duration_ms -1 is not a duration above 0 and at most 10000 ms): none is kept to."
        + " Its status said \"floor\": {\"min_duration_ms\": -1, \"min_length\": 0.05}\n",
        bad.err());
    arrived(1);
  }
}
