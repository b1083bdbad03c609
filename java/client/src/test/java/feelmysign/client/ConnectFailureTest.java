package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;

import com.hivemq.client.mqtt.exceptions.ConnectionClosedException;
import com.hivemq.client.mqtt.exceptions.ConnectionFailedException;
import java.net.ConnectException;
import java.net.UnknownHostException;
import org.junit.jupiter.api.Test;

/** The sentences a sketch and its status show when the broker cannot be reached. */
class ConnectFailureTest {
  private static final String URL = "mqtt://broker.local:1883";

  @Test
  void aRefusedConnectionIsTheReferencesSentence() {
    Throwable netty = new ConnectException("Connection refused: broker.local/10.0.0.5:1883");
    assertEquals(
        "Nothing accepts connections at " + URL + " (connection refused): start one with"
            + " 'feelmysign broker' or 'make up', or give the right broker URL.",
        ConnectFailure.sentence(BrokerUrl.parse(URL), new ConnectionFailedException(netty)));
  }

  @Test
  void anUnknownHostIsNamed() {
    assertEquals(
        "Cannot find the host 'broker.local' of " + URL + ": check the host name in the broker"
            + " URL.",
        ConnectFailure.sentence(BrokerUrl.parse(URL), new ConnectionFailedException(new UnknownHostException())));
  }

  @Test
  void aListenerThatIsNotMqttIsSaidSo() {
    BrokerUrl webSocket = BrokerUrl.parse("ws://h:9001");
    assertEquals(
        webSocket + " closed the connection before answering the login: is that port an MQTT"
            + " broker's WebSocket listener? (The local broker's ports are in its"
            + " credentials.json.)",
        ConnectFailure.sentence(webSocket, new ConnectionClosedException("closed")));
  }

  @Test
  void anyOtherFailureKeepsItsMessageWithoutClassNames() {
    Throwable netty =
        new IllegalStateException(
            "io.netty.channel.AbstractChannel$AnnotatedSocketException: Network is unreachable");
    assertEquals(
        "Cannot connect to " + URL + " (Network is unreachable): check the broker URL, or start"
            + " one with 'feelmysign broker' or 'make up', or give the right broker URL.",
        ConnectFailure.sentence(BrokerUrl.parse(URL), new ConnectionFailedException(netty)));
  }
}
