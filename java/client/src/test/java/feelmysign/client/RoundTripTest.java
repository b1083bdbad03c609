package feelmysign.client;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import feelmysign.json.PyJson;
import feelmysign.protocol.Stroke;
import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
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
  private static final long WAIT_S = 60; // generous: the machine running the tests may be busy
  private static final String SLEEVE = "java-test";

  private Path state;
  private Process broker;
  private Process sleeve;
  private String mqttUrl;
  private String mqttsUrl;
  private String caFingerprint;
  private String senderUser;
  private String senderPassword;

  private static Path repository() {
    for (Path dir = Path.of("").toAbsolutePath(); dir != null; dir = dir.getParent()) {
      if (Files.isDirectory(dir.resolve("testdata")) && Files.isDirectory(dir.resolve("python"))) {
        return dir;
      }
    }
    throw new IllegalStateException("not inside the feelmysign repository");
  }

  @BeforeAll
  void startBrokerAndSleeve(@TempDir Path dir) throws IOException, InterruptedException {
    state = dir;
    Path feelmysign = repository().resolve(".venv/bin/feelmysign");
    if (!Files.isExecutable(feelmysign)) {
      fail(feelmysign + " is missing: run 'make .venv/.installed-stamp' (make java-test does)");
    }
    broker =
        new ProcessBuilder(
                feelmysign.toString(), "broker", "--state-dir", state.toString(),
                "--port", "0", "--ws-port", "0", "--sleeve-id", SLEEVE,
                // TLS too, on loopback, with the broker's own CA: the --lan set-up.
                "--host", "127.0.0.1", "--tls-port", "0")
            .redirectErrorStream(true)
            .start();
    BufferedReader out =
        new BufferedReader(new InputStreamReader(broker.getInputStream(), StandardCharsets.UTF_8));
    long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(WAIT_S);
    StringBuilder said = new StringBuilder();
    for (String line; (line = out.readLine()) != null; ) {
      said.append(line).append('\n');
      if (line.startsWith("Ready.")) {
        break;
      }
      if (System.nanoTime() > deadline) {
        fail("feelmysign broker did not get ready:\n" + said);
      }
    }
    assertTrue(said.toString().contains("Ready."), "feelmysign broker failed:\n" + said);
    // Keep draining its output, so that it never blocks on a full pipe.
    Thread drain =
        new Thread(
            () -> {
              try {
                out.lines().forEach(line -> {});
              } catch (java.io.UncheckedIOException closed) {
                // The broker stopped.
              }
            },
            "broker-output");
    drain.setDaemon(true);
    drain.start();
    Path credentials = state.resolve("credentials.json");
    @SuppressWarnings("unchecked")
    Map<String, Object> document =
        (Map<String, Object>) PyJson.loads(Files.readString(credentials));
    mqttUrl = (String) document.get("mqtt_url");
    mqttsUrl = (String) document.get("mqtts_url");
    caFingerprint = (String) document.get("ca_fingerprint");
    @SuppressWarnings("unchecked")
    Map<String, Object> sender = (Map<String, Object>) document.get("sender");
    senderUser = (String) sender.get("username");
    senderPassword = (String) sender.get("password");
    sleeve =
        new ProcessBuilder(
                feelmysign.toString(), "sleeve", "--credentials", credentials.toString(),
                "--backend", "sim", "--no-legacy", "--log-level", "warning")
            .redirectErrorStream(true)
            .redirectOutput(state.resolve("sleeve.log").toFile())
            .start();
  }

  @AfterAll
  void stopThem() throws InterruptedException {
    for (Process process : new Process[] {sleeve, broker}) {
      if (process != null) {
        process.destroy(); // SIGTERM: the sleeve stops with every motor off
        if (!process.waitFor(WAIT_S, TimeUnit.SECONDS)) {
          process.destroyForcibly();
        }
      }
    }
  }

  /** Everything the client tells, in order, to wait on. */
  private static final class Heard implements SleeveClient.Listener {
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
    public void status(String payload) {
      all.add("status " + payload);
    }

    @Override
    public void event(SleeveEvent event) {
      all.add(event);
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
    return SleeveClient.builder(mqttUrl)
        .login(senderUser, password)
        .sleeveId(SLEEVE)
        .listener(heard)
        .build();
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
    try (SleeveClient client =
        SleeveClient.builder(mqttsUrl)
            .login(senderUser, senderPassword)
            .sleeveId(SLEEVE)
            .caCertificate(state.resolve("tls/ca.pem"))
            .listener(heard)
            .build()) {
      playsOneStroke(client, heard);
    }
  }

  @Test
  void overTlsWithTheCasFingerprint() throws InterruptedException {
    Heard heard = new Heard();
    try (SleeveClient client =
        SleeveClient.builder(mqttsUrl)
            .login(senderUser, senderPassword)
            .sleeveId(SLEEVE)
            .caFingerprint(caFingerprint)
            .listener(heard)
            .build()) {
      playsOneStroke(client, heard);
    }
  }

  @Test
  void aCertificateThatDoesNotMatchIsToldAndRetried() throws InterruptedException {
    Heard heard = new Heard();
    String other = "0".repeat(64);
    try (SleeveClient client =
        SleeveClient.builder(mqttsUrl)
            .login(senderUser, senderPassword)
            .sleeveId(SLEEVE)
            .caFingerprint(other)
            .listener(heard)
            .build()) {
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
    try (SleeveClient client = client(heard, senderPassword)) {
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
    try (SleeveClient client = client(heard, senderPassword)) {
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
    try (SleeveClient client = client(heard, senderPassword + "x")) {
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
        SleeveClient.builder(mqttUrl).sleeveId(SLEEVE).listener(heard).build()) {
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
