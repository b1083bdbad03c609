package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.junit.jupiter.api.Test;

/** The client's parts that need no broker: URLs, the outbox, events. */
class ClientPartsTest {
  @Test
  void brokerUrlsOfEveryScheme() {
    assertEquals(new BrokerUrl("mqtt", "127.0.0.1", 1883, ""), BrokerUrl.parse("mqtt://127.0.0.1"));
    assertEquals(new BrokerUrl("mqtts", "sleeve.local", 8883, ""), BrokerUrl.parse("mqtts://sleeve.local"));
    BrokerUrl ws = BrokerUrl.parse("ws://host:9001/mqtt");
    assertTrue(ws.webSocket());
    assertEquals("/mqtt", ws.path());
    assertTrue(BrokerUrl.parse("wss://host").tls());
    assertEquals(443, BrokerUrl.parse("wss://host").port());
    IllegalArgumentException http =
        assertThrows(IllegalArgumentException.class, () -> BrokerUrl.parse("http://host"));
    assertTrue(http.getMessage().contains("must start with mqtt://, mqtts://, ws:// or wss://"));
    assertThrows(IllegalArgumentException.class, () -> BrokerUrl.parse("mqtt://"));
    assertThrows(IllegalArgumentException.class, () -> BrokerUrl.parse("not a url"));
  }

  @Test
  void outboxKeepsOrderUntilAcknowledged() {
    Outbox<String> outbox = new Outbox<>();
    outbox.add("a", 0);
    outbox.add("b", 1);
    outbox.add("c", 2);
    List<Outbox.Entry<String>> taken = outbox.takeQueued();
    assertEquals(3, outbox.size(), "in flight still counts");
    outbox.ack(taken.get(1).id());
    outbox.fail(taken.get(2).id());
    outbox.requeueInFlight();
    assertEquals(List.of("a", "c"), outbox.takeQueued().stream().map(Outbox.Entry::item).toList());
    outbox.add("d", 10);
    assertEquals(List.of("d"), outbox.dropQueued((item, entry) -> entry.addedMs() > 5));
    assertEquals(2, outbox.size());
  }

  @Test
  void eventsAreReadWithTheirFields() {
    SleeveEvent event =
        SleeveEvent.parse(
            "{\"type\":\"rejected\",\"reason\":\"outside_grid\",\"message\":\"m\",\"drawing\":\"d\",\"seq\":3.0}");
    assertEquals("rejected", event.type());
    assertEquals("outside_grid", event.reason());
    assertEquals(3L, event.seq());
    assertEquals("d", event.drawing());
    assertNull(SleeveEvent.parse("[1]"));
    assertNull(SleeveEvent.parse("{\"type\":5}"));
    assertNull(SleeveEvent.parse("not json"));
  }

  @Test
  void theWearersCutsAndRefusalsAreToldApart() {
    SleeveEvent cut =
        SleeveEvent.parse(
            "{\"type\":\"cancelled\",\"reason\":\"cancelled\",\"message\":\"m\",\"seq\":1,"
                + "\"started\":true,\"by\":\"wearer\"}");
    assertTrue(cut.byWearer());
    SleeveEvent stop =
        SleeveEvent.parse("{\"type\":\"cancelled\",\"reason\":\"cancelled\",\"message\":\"m\"}");
    assertFalse(stop.byWearer(), "a sender's cancel has no by");
    for (String reason : List.of(SleeveEvent.PAUSED, SleeveEvent.DO_NOT_DISTURB)) {
      SleeveEvent refused =
          SleeveEvent.parse(
              "{\"type\":\"rejected\",\"reason\":\"" + reason + "\",\"message\":\"m\"}");
      assertTrue(refused.refusedByWearer(), reason);
    }
    assertFalse(
        SleeveEvent.parse("{\"type\":\"rejected\",\"reason\":\"stale\",\"message\":\"m\"}")
            .refusedByWearer());
  }
}
