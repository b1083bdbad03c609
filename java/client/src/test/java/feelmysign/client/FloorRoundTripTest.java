package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.mqtt3.Mqtt3BlockingClient;
import feelmysign.testing.LiveSleeve;
import java.io.IOException;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.CopyOnWriteArrayList;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * The sleeve's floor reaches a Java sender through a real Mosquitto started by {@code feelmysign
 * broker}, in the retained status exactly as docs/protocol.md writes it, published here with the
 * sleeve's own account; and is kept as the page keeps it: through the last will, a cleared status
 * and the broker going away.
 */
class FloorRoundTripTest {
  private static final String SLEEVE = "java-floor";
  private LiveSleeve live;
  private Mqtt3BlockingClient sleeve;

  @AfterEach
  void stopIt() throws InterruptedException {
    if (sleeve != null && sleeve.getState().isConnected()) {
      sleeve.disconnect();
    }
    if (live != null) {
      live.close();
    }
  }

  private void startBroker(Path state) throws IOException {
    live = LiveSleeve.brokerOnly(state, SLEEVE);
    URI url = URI.create(live.mqttUrl());
    sleeve =
        MqttClient.builder()
            .useMqttVersion3()
            .identifier("test-sleeve-floor-" + ProcessHandle.current().pid())
            .serverHost(url.getHost())
            .serverPort(url.getPort())
            .buildBlocking();
    sleeve
        .connectWith()
        .simpleAuth()
        .username(live.sleeveUser())
        .password(live.sleevePassword().getBytes(StandardCharsets.UTF_8))
        .applySimpleAuth()
        .send();
  }

  private void publishStatus(String json) {
    sleeve
        .publishWith()
        .topic("feelmysign/" + SLEEVE + "/status")
        .qos(MqttQos.AT_LEAST_ONCE)
        .retain(true)
        .payload(json.getBytes(StandardCharsets.UTF_8))
        .send();
  }

  private static String status(boolean online, String floor) {
    return "{\"online\": " + online + ", \"sleeve_id\": \"" + SLEEVE + "\", \"version\": \"0.1.0\","
        + " \"backend\": \"sim\", \"layout\": {\"name\": \"paper-sleeve\", \"rows\": 3,"
        + " \"columns\": 4, \"spacing_cm\": 3.0, \"actuator_type\": \"ERM\"}, \"at_ms\":"
        + " 1795326267664" + (floor == null ? "" : ", \"floor\": " + floor) + "}";
  }

  /** What the client told, in order: floors (or "none") and ignored floors' sentences. */
  private static final class Heard implements SleeveClient.Listener {
    final List<Object> told = new CopyOnWriteArrayList<>();
    final List<String> statuses = new CopyOnWriteArrayList<>();

    @Override
    public void status(String payload) {
      statuses.add(payload);
    }

    @Override
    public void floor(SleeveFloor floor) {
      told.add(floor == null ? "none" : floor);
    }

    @Override
    public void floorIgnored(String sentence) {
      told.add(sentence);
    }
  }

  @Test
  void theStatusFloorIsReadKeptAndAMalformedOneIgnoredWithASentence(@TempDir Path state)
      throws Exception {
    startBroker(state);
    publishStatus(status(true,
        "{\"min_duration_ms\": 118.4, \"min_length\": 0.62, \"wearer\": \"P01\"}"));
    Heard heard = new Heard();
    SleeveClient client = live.client(live.senderPassword()).listener(heard).build();
    try {
      client.connect();
      SleeveFloor p01 = new SleeveFloor(118.4, 0.62, "P01");
      LiveSleeve.waitFor(() -> heard.told.size() >= 1, "the floor with a wearer");
      assertEquals(List.of(p01), heard.told);
      assertEquals(p01, client.floor());

      // The wearer file taken away: the motors' floor alone.
      publishStatus(status(true, "{\"min_duration_ms\": 73.701, \"min_length\": 0.05}"));
      SleeveFloor motors = new SleeveFloor(73.701, 0.05, null);
      LiveSleeve.waitFor(() -> heard.told.size() >= 2, "the motors' floor");
      assertEquals(motors, heard.told.get(1));

      // A floor not understood: said once, even when republished, and the one before is kept.
      String bad = status(true, "{\"min_duration_ms\": -5, \"min_length\": 0.05}");
      publishStatus(bad);
      publishStatus(bad);
      LiveSleeve.waitFor(() -> heard.told.size() >= 3, "the sentence for the malformed floor");
      String said = (String) heard.told.get(2);
      assertTrue(said.startsWith("the sleeve's floor in its status is not understood and was"
          + " ignored (min_duration_ms -5 is not a duration above 0 and at most 10000 ms): the"
          + " floor it said before is kept."), said);
      assertEquals(motors, client.floor());

      // The last will (no floor), then a cleared status: the floor is kept through both.
      publishStatus("{\"online\": false, \"sleeve_id\": \"" + SLEEVE + "\"}");
      publishStatus("");
      // An online status from a sleeve older than the floor: none is known any more.
      publishStatus(status(true, null));
      LiveSleeve.waitFor(() -> heard.told.size() >= 4, "no floor from an older sleeve");
      assertEquals("none", heard.told.get(3));
      assertEquals(7, heard.statuses.size(), heard.statuses.toString());
      assertNull(client.floor());

      publishStatus(status(true,
          "{\"min_duration_ms\": 118.4, \"min_length\": 0.62, \"wearer\": \"P01\"}"));
      LiveSleeve.waitFor(() -> heard.told.size() >= 5, "the wearer's floor again");
      assertEquals(List.of(p01, motors, said, "none", p01), heard.told);

      // The broker goes away: the sleeve's floor is still known.
      sleeve.disconnect();
      live.close();
      live = null;
      LiveSleeve.waitFor(() -> !client.connected(), "the broker's going away");
      assertEquals(p01, client.floor());
    } finally {
      client.close();
    }
  }
}
