package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.mqtt3.Mqtt3BlockingClient;
import feelmysign.testing.LiveSleeve;
import java.io.IOException;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.util.concurrent.BlockingQueue;
import java.util.concurrent.LinkedBlockingQueue;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;

/**
 * The wearer's choice reaches a Java sender typed, through a real Mosquitto started by {@code
 * feelmysign broker}. The sleeve's retained status, with {@code controls} exactly as
 * docs/protocol.md writes it, is published here with the sleeve's own account: it stands in for
 * the sleeve daemon's status until the sleeve's side of the wearer's controls publishes it.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class WearerRoundTripTest {
  private static final String SLEEVE = "java-wearer";
  private LiveSleeve live;
  private Mqtt3BlockingClient sleeve;

  @BeforeAll
  void startBroker(@TempDir Path state) throws IOException {
    live = LiveSleeve.brokerOnly(state, SLEEVE);
    URI url = URI.create(live.mqttUrl());
    sleeve =
        MqttClient.builder()
            .useMqttVersion3()
            .identifier("test-sleeve-" + ProcessHandle.current().pid())
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

  @AfterAll
  void stopIt() throws InterruptedException {
    if (sleeve != null) {
      sleeve.disconnect();
    }
    if (live != null) {
      live.close();
    }
  }

  private void publishStatus(String controls) {
    String status =
        "{\"online\": true, \"sleeve_id\": \"" + SLEEVE + "\", \"layout\": {\"rows\": 3,"
            + " \"columns\": 4}, \"controls\": " + controls + "}";
    sleeve
        .publishWith()
        .topic("feelmysign/" + SLEEVE + "/status")
        .qos(MqttQos.AT_LEAST_ONCE)
        .retain(true)
        .payload(status.getBytes(StandardCharsets.UTF_8))
        .send();
  }

  private static WearerState next(BlockingQueue<WearerState> heard) throws InterruptedException {
    WearerState state = heard.poll(LiveSleeve.WAIT_S, TimeUnit.SECONDS);
    if (state == null) {
      fail("no wearer state within " + LiveSleeve.WAIT_S + " s");
    }
    return state;
  }

  @Test
  void theStatusCallbackIsFollowedByTheWearersStateTyped() throws InterruptedException {
    publishStatus(
        "{\"paused\": true, \"paused_by\": \"button\", \"ceiling\": 0.6,"
            + " \"do_not_disturb_until_ms\": null}");
    BlockingQueue<WearerState> heard = new LinkedBlockingQueue<>();
    BlockingQueue<String> statuses = new LinkedBlockingQueue<>();
    SleeveClient.Listener listener =
        new SleeveClient.Listener() {
          @Override
          public void status(String payload) {
            statuses.add(payload);
          }

          @Override
          public void wearer(WearerState state) {
            // The status came first: a sketch reading both sees them in order.
            assertTrue(statuses.stream().anyMatch(s -> s.contains("\"controls\"")));
            heard.add(state);
          }
        };
    try (SleeveClient client =
        live.client(live.senderPassword()).sleeveId(SLEEVE).listener(listener).build()) {
      client.connect();
      assertEquals(new WearerState(true, "button", 0.6, null), next(heard));
      long untilMs = System.currentTimeMillis() + 30 * 60_000;
      publishStatus(
          "{\"paused\": false, \"paused_by\": null, \"ceiling\": null,"
              + " \"do_not_disturb_until_ms\": " + untilMs + "}");
      WearerState dnd = next(heard);
      assertEquals(new WearerState(false, null, null, untilMs), dnd);
      assertTrue(dnd.holds(System.currentTimeMillis()));
      publishStatus("{\"paused\": \"yes\"}");
      publishStatus(
          "{\"paused\": false, \"paused_by\": null, \"ceiling\": null,"
              + " \"do_not_disturb_until_ms\": null}");
      // Controls not understood are not passed on: the next state heard is the resumed one.
      assertEquals(new WearerState(false, null, null, null), next(heard));
    }
  }
}
