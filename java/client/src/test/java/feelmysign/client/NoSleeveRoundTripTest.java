package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.mqtt3.Mqtt3BlockingClient;
import feelmysign.protocol.Stroke;
import feelmysign.testing.LiveSleeve;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * An id no sleeve listens on is said (Listener.noSleeve) through a real Mosquitto started by
 * {@code feelmysign broker}: the broker holds no retained status for it, so none comes after the
 * subscription. Said once after {@link SleeveClient#STATUS_WAIT_MS}, once more when strokes are
 * sent (not per stroke), not while a sleeve's status is held, and again when the status is
 * cleared. The sleeve's status is published here with the sleeve's own account.
 */
class NoSleeveRoundTripTest {
  private static final String SLEEVE = "java-nobody";
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

  private void publishStatus(String json) {
    if (sleeve == null) {
      URI url = URI.create(live.mqttUrl());
      sleeve =
          MqttClient.builder()
              .useMqttVersion3()
              .identifier("test-sleeve-nobody-" + ProcessHandle.current().pid())
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
    sleeve
        .publishWith()
        .topic("feelmysign/" + SLEEVE + "/status")
        .qos(MqttQos.AT_LEAST_ONCE)
        .retain(true)
        .payload(json.getBytes(StandardCharsets.UTF_8))
        .send();
  }

  private static final class Heard implements SleeveClient.Listener {
    final List<String> said = new CopyOnWriteArrayList<>();
    final List<String> statuses = new CopyOnWriteArrayList<>();
    final List<Stroke> acked = new CopyOnWriteArrayList<>();
    volatile long connectedNs;

    @Override
    public void broker(SleeveClient.State state, String detail) {
      if (state == SleeveClient.State.CONNECTED && connectedNs == 0) {
        connectedNs = System.nanoTime();
      }
    }

    @Override
    public void status(String payload) {
      statuses.add(payload);
    }

    @Override
    public void noSleeve(String sentence) {
      said.add(sentence);
    }

    @Override
    public void acked(Stroke stroke) {
      acked.add(stroke);
    }
  }

  private static void sendSome(SleeveClient client, Heard heard, int count)
      throws InterruptedException {
    int before = heard.acked.size();
    client.newDrawing();
    for (int k = 0; k < count; k++) {
      client.send(new Stroke(0, 0, 3, 2, 100));
    }
    LiveSleeve.waitFor(() -> heard.acked.size() == before + count, "the broker's PUBACKs");
  }

  @Test
  void anIdWithNoStatusIsSaidOnceAfterTheWaitAndOnceMoreForStrokes(@TempDir Path state)
      throws Exception {
    live = LiveSleeve.brokerOnly(state, SLEEVE);
    Heard heard = new Heard();
    SleeveClient client = live.client(live.senderPassword()).listener(heard).build();
    String sentence = SleeveClient.noSleeveSentence(SLEEVE);
    try {
      client.connect();
      LiveSleeve.waitFor(() -> heard.said.size() == 1, "the sentence for an id with no status");
      long afterMs = TimeUnit.NANOSECONDS.toMillis(System.nanoTime() - heard.connectedNs);
      assertTrue(afterMs >= SleeveClient.STATUS_WAIT_MS - 100 && afterMs < 10_000,
          "said " + afterMs + " ms after connecting");
      assertEquals(List.of(sentence), heard.said);
      assertEquals(List.of(), heard.statuses);

      // Strokes sent there: said once more, however many.
      sendSome(client, heard, 5);
      sendSome(client, heard, 5);
      assertEquals(List.of(sentence, sentence), heard.said);

      // A sleeve reports on the id: strokes are sent without a word.
      String online = "{\"online\": true, \"sleeve_id\": \"" + SLEEVE + "\"}";
      publishStatus(online);
      LiveSleeve.waitFor(() -> heard.statuses.contains(online), "the sleeve's status");
      sendSome(client, heard, 3);
      assertEquals(2, heard.said.size(), heard.said.toString());

      // Its status cleared: said at once, and once more for the strokes after it.
      publishStatus("");
      LiveSleeve.waitFor(() -> heard.said.size() == 3, "the sentence for a cleared status");
      sendSome(client, heard, 3);
      assertEquals(List.of(sentence, sentence, sentence, sentence), heard.said);
    } finally {
      client.close();
    }
  }

  @Test
  void anIdWithARetainedStatusIsNotSaid(@TempDir Path state) throws Exception {
    live = LiveSleeve.brokerOnly(state, SLEEVE);
    publishStatus("{\"online\": false, \"sleeve_id\": \"" + SLEEVE + "\"}");
    Heard heard = new Heard();
    SleeveClient client = live.client(live.senderPassword()).listener(heard).build();
    try {
      client.connect();
      LiveSleeve.waitFor(() -> !heard.statuses.isEmpty(), "the retained status");
      Thread.sleep(SleeveClient.STATUS_WAIT_MS + 1000);
      sendSome(client, heard, 3);
      assertEquals(List.of(), heard.said);
    } finally {
      client.close();
    }
  }
}
