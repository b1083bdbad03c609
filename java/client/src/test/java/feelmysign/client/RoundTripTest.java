package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import feelmysign.protocol.Stroke;
import feelmysign.testing.LiveSleeve;
import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.BlockingQueue;
import java.util.concurrent.LinkedBlockingQueue;
import java.util.concurrent.TimeUnit;
import java.util.function.Predicate;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;

/**
 * The Java client against a real Mosquitto started by {@code feelmysign broker} and a real
 * {@code feelmysign sleeve --backend sim} from the repository's .venv: strokes sent from Java
 * come back as played events, Stop cancels a drawing mid-way, a wrong password is told once.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class RoundTripTest {
  private static final long WAIT_S = LiveSleeve.WAIT_S;
  private static final String SLEEVE = "java-test";

  private LiveSleeve live;

  @BeforeAll
  void startBrokerAndSleeve(@TempDir Path state) throws IOException {
    // TLS too, on loopback, with the broker's own CA: the --lan set-up.
    live =
        LiveSleeve.start(
            state,
            SLEEVE,
            List.of("--host", "127.0.0.1", "--tls-port", "0"),
            List.of("--no-legacy"));
  }

  @AfterAll
  void stopThem() throws InterruptedException {
    if (live != null) {
      live.close();
    }
  }

  /** Everything the client tells, in order, to wait on. */
  private static final class Heard extends LiveSleeve.Listening {
    final BlockingQueue<Object> all = new LinkedBlockingQueue<>();
    final List<String> brokerSaid = new ArrayList<>();

    @Override
    public void broker(SleeveClient.State state, String detail) {
      synchronized (brokerSaid) {
        brokerSaid.add(state + ": " + detail);
      }
      all.add(state);
    }

    @Override
    protected void heard(Object eventOrStatus) {
      all.add(eventOrStatus);
    }

    @Override
    public void acked(Stroke stroke) {
      all.add(stroke);
    }

    <T> T next(Class<T> kind, Predicate<T> wanted, String what) throws InterruptedException {
      long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(WAIT_S);
      while (true) {
        long left = deadline - System.nanoTime();
        Object item = all.poll(Math.max(0, left), TimeUnit.NANOSECONDS);
        if (item == null) {
          fail("no " + what + " within " + WAIT_S + " s");
        }
        if (kind.isInstance(item) && wanted.test(kind.cast(item))) {
          return kind.cast(item);
        }
      }
    }
  }

  private SleeveClient client(Heard heard, String password) {
    return live.client(password).listener(heard).build();
  }

  /** A client over TLS, trusting what {@code trust} sets (a CA file or fingerprint). */
  private SleeveClient tlsClient(
      Heard heard, java.util.function.UnaryOperator<SleeveClient.Builder> trust) {
    SleeveClient.Builder builder =
        SleeveClient.builder(live.mqttsUrl())
            .login(live.senderUser(), live.senderPassword())
            .sleeveId(SLEEVE)
            .listener(heard);
    return trust.apply(builder).build();
  }

  /** One stroke over the connection {@code client} makes: it comes back played. */
  private static void playsOneStroke(SleeveClient client, Heard heard) throws InterruptedException {
    client.connect();
    heard.next(String.class, s -> s.contains("\"online\": true"), "the sleeve online");
    String drawing = client.newDrawing();
    client.send(new Stroke(0, 0, 3, 2, 300));
    heard.next(
        SleeveEvent.class,
        e -> finished(e) && drawing.equals(e.drawing()) && e.seq() == 0,
        "the stroke played");
  }

  @Test
  void overTlsWithTheBrokersCa() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client = tlsClient(heard, b -> b.caCertificate(live.caCertificate()))) {
      playsOneStroke(client, heard);
    }
  }

  @Test
  void overTlsWithTheCasFingerprint() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client = tlsClient(heard, b -> b.caFingerprint(live.caFingerprint()))) {
      playsOneStroke(client, heard);
    }
  }

  @Test
  void aCertificateThatDoesNotMatchIsToldAndRetried() throws InterruptedException {
    Heard heard = new Heard();
    String other = "0".repeat(64);
    try (SleeveClient client = tlsClient(heard, b -> b.caFingerprint(other))) {
      client.connect();
      heard.next(SleeveClient.State.class, s -> s == SleeveClient.State.OFFLINE, "offline");
      Thread.sleep(3 * SleeveClient.RECONNECT_PERIOD_MS);
      synchronized (heard.brokerSaid) {
        long told =
            heard.brokerSaid.stream().filter(s -> s.contains("certificate this client does not trust")).count();
        assertEquals(1, told, heard.brokerSaid.toString());
      }
      assertTrue(!client.connected());
      assertTrue(!client.loginRefused(), "a certificate problem is retried");
      // A stroke drawn meanwhile waits in the outbox.
      client.send(new Stroke(0, 0, 1, 1, 200));
      assertEquals(1, client.unsent());
    }
  }

  private static boolean finished(SleeveEvent e) {
    return e.type().equals(SleeveEvent.PLAYED) || e.type().equals(SleeveEvent.ADJUSTED);
  }

  @Test
  void strokesSentFromJavaArePlayed() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client = client(heard, live.senderPassword())) {
      client.connect();
      heard.next(String.class, s -> s.contains("\"online\": true"), "the sleeve online");
      String drawing = client.newDrawing();
      client.send(new Stroke(0, 0, 2, 0, 300));
      client.send(new Stroke(2, 0, 2, 2, 300));
      client.send(new Stroke(2, 2, 0, 2, 300));
      for (long seq = 0; seq < 3; seq++) {
        long wanted = seq;
        SleeveEvent event =
            heard.next(
                SleeveEvent.class,
                e -> finished(e) && drawing.equals(e.drawing()) && e.seq() == wanted,
                "played event of stroke " + seq);
        assertNotNull(event.fields().get("received_at_ms"));
      }
      assertEquals(0, client.unsent());
    }
  }

  @Test
  void stopCancelsTheDrawingMidway() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client = client(heard, live.senderPassword())) {
      client.connect();
      heard.next(String.class, s -> s.contains("\"online\": true"), "the sleeve online");
      String drawing = client.newDrawing();
      Stroke sent = client.send(new Stroke(0, 1, 3, 1, 8000));
      heard.next(Stroke.class, s -> s.equals(sent), "the broker's PUBACK");
      // The sleeve tells "played" as the stroke starts; Stop comes while it plays.
      heard.next(
          SleeveEvent.class,
          e -> drawing.equals(e.drawing()) && e.type().equals(SleeveEvent.PLAYED),
          "the long stroke started");
      client.stop();
      SleeveEvent cancelled =
          heard.next(
              SleeveEvent.class,
              e -> drawing.equals(e.drawing()) && e.type().equals(SleeveEvent.CANCELLED),
              "the long stroke cancelled");
      // Stopped while playing: a stroke already over would have nothing left to cancel.
      assertEquals(Boolean.TRUE, cancelled.fields().get("started"), cancelled.fields().toString());
    }
  }

  @Test
  void aWrongPasswordIsToldOnceAndNotRetried() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client = client(heard, live.senderPassword() + "x")) {
      client.connect();
      heard.next(SleeveClient.State.class, s -> s == SleeveClient.State.OFFLINE, "offline");
      assertTrue(client.loginRefused());
      Thread.sleep(3 * SleeveClient.RECONNECT_PERIOD_MS);
      synchronized (heard.brokerSaid) {
        long refusals = heard.brokerSaid.stream().filter(s -> s.contains("refused the login")).count();
        assertEquals(1, refusals, heard.brokerSaid.toString());
      }
      assertTrue(!client.connected());
    }
  }

  @Test
  void aLoginWithoutAUserNameIsSaidSoWithWhereTheLoginIs() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client =
        SleeveClient.builder(live.mqttUrl()).sleeveId(SLEEVE).listener(heard).build()) {
      client.connect();
      heard.next(SleeveClient.State.class, s -> s == SleeveClient.State.OFFLINE, "offline");
      assertTrue(client.loginRefused());
      synchronized (heard.brokerSaid) {
        assertTrue(heard.brokerSaid.stream().anyMatch(s -> s.contains("refused a login without a"
            + " user name") && s.contains("credentials.json")), heard.brokerSaid.toString());
        assertTrue(heard.brokerSaid.stream().noneMatch(s -> s.contains("'null'")),
            heard.brokerSaid.toString());
      }
    }
  }
}
