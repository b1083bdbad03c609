package feelmysign.testing;

import feelmysign.client.SleeveClient;
import feelmysign.client.SleeveEvent;
import feelmysign.json.PyJson;
import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.io.UncheckedIOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.concurrent.TimeUnit;
import java.util.function.BooleanSupplier;

/**
 * A real Mosquitto started by {@code feelmysign broker} and a real {@code feelmysign sleeve
 * --backend sim}, both from the repository's .venv, for the tests of every module that talks to
 * a sleeve (the client, the command line, the Processing library). Close it: the sleeve stops
 * first (SIGTERM: every motor off), then the broker.
 */
public final class LiveSleeve implements AutoCloseable {
  /** Generous: the machine running the tests may be busy. */
  public static final long WAIT_S = 60;

  private final Path state;
  private final String sleeveId;
  private final Process broker;
  private final Process sleeve;
  private final Map<String, Object> document;

  /** The repository's root, found upwards from the working directory (a module's folder). */
  public static Path repository() {
    for (Path dir = Path.of("").toAbsolutePath(); dir != null; dir = dir.getParent()) {
      if (Files.isDirectory(dir.resolve("testdata")) && Files.isDirectory(dir.resolve("python"))) {
        return dir;
      }
    }
    throw new IllegalStateException("not inside the feelmysign repository");
  }

  /** The reference's command line, {@code .venv/bin/feelmysign}; an error saying how to get it. */
  public static Path feelmysign() {
    Path command = repository().resolve(".venv/bin/feelmysign");
    if (!Files.isExecutable(command)) {
      throw new IllegalStateException(
          command + " is missing: run 'make .venv/.installed-stamp' (make java-test does)");
    }
    return command;
  }

  /**
   * Starts a broker keeping its state in {@code state} (its credentials.json, TLS files) and a
   * simulated sleeve {@code sleeveId} logged in with its credentials.
   *
   * @param brokerOptions more options of {@code feelmysign broker} (e.g. a TLS port)
   * @param sleeveOptions more options of {@code feelmysign sleeve} (e.g. --no-legacy)
   */
  public static LiveSleeve start(
      Path state, String sleeveId, List<String> brokerOptions, List<String> sleeveOptions)
      throws IOException {
    List<String> brokerCommand =
        new ArrayList<>(
            List.of(
                feelmysign().toString(), "broker", "--state-dir", state.toString(),
                "--port", "0", "--ws-port", "0", "--sleeve-id", sleeveId));
    brokerCommand.addAll(brokerOptions);
    Process broker = new ProcessBuilder(brokerCommand).redirectErrorStream(true).start();
    try {
      awaitReady(broker);
      Path credentials = state.resolve("credentials.json");
      @SuppressWarnings("unchecked")
      Map<String, Object> document =
          (Map<String, Object>) PyJson.loads(Files.readString(credentials));
      List<String> sleeveCommand =
          new ArrayList<>(
              List.of(
                  feelmysign().toString(), "sleeve", "--credentials", credentials.toString(),
                  "--backend", "sim", "--log-level", "warning"));
      sleeveCommand.addAll(sleeveOptions);
      Process sleeve =
          new ProcessBuilder(sleeveCommand)
              .redirectErrorStream(true)
              .redirectOutput(state.resolve("sleeve.log").toFile())
              .start();
      return new LiveSleeve(state, sleeveId, broker, sleeve, document);
    } catch (IOException | RuntimeException error) {
      stop(broker);
      throw error;
    }
  }

  /**
   * Starts a broker only, keeping its state in {@code state}: no sleeve, so the test publishes
   * the sleeve's messages itself with {@link #sleeveUser()} and {@link #sleevePassword()}.
   */
  public static LiveSleeve brokerOnly(Path state, String sleeveId) throws IOException {
    Process broker =
        new ProcessBuilder(
                feelmysign().toString(), "broker", "--state-dir", state.toString(),
                "--port", "0", "--ws-port", "0", "--sleeve-id", sleeveId)
            .redirectErrorStream(true)
            .start();
    try {
      awaitReady(broker);
      @SuppressWarnings("unchecked")
      Map<String, Object> document =
          (Map<String, Object>) PyJson.loads(Files.readString(state.resolve("credentials.json")));
      return new LiveSleeve(state, sleeveId, broker, null, document);
    } catch (IOException | RuntimeException error) {
      stop(broker);
      throw error;
    }
  }

  private LiveSleeve(
      Path state, String sleeveId, Process broker, Process sleeve, Map<String, Object> document) {
    this.state = state;
    this.sleeveId = sleeveId;
    this.broker = broker;
    this.sleeve = sleeve;
    this.document = document;
  }

  /** Reads the broker's output until it says "Ready.", then drains it (a full pipe blocks it). */
  private static void awaitReady(Process broker) throws IOException {
    BufferedReader out =
        new BufferedReader(new InputStreamReader(broker.getInputStream(), StandardCharsets.UTF_8));
    StringBuilder said = new StringBuilder();
    for (String line; (line = out.readLine()) != null; ) {
      said.append(line).append('\n');
      if (line.startsWith("Ready.")) {
        Thread drain =
            new Thread(
                () -> {
                  try {
                    out.lines().forEach(rest -> {});
                  } catch (UncheckedIOException closed) {
                    // The broker stopped.
                  }
                },
                "broker-output");
        drain.setDaemon(true);
        drain.start();
        return;
      }
    }
    throw new IllegalStateException("feelmysign broker did not get ready:\n" + said);
  }

  public Path state() {
    return state;
  }

  public String sleeveId() {
    return sleeveId;
  }

  /** The broker's credentials.json, as {@code --credentials} takes it. */
  public Path credentials() {
    return state.resolve("credentials.json");
  }

  /** The broker's CA certificate (with a TLS port). */
  public Path caCertificate() {
    return state.resolve("tls/ca.pem");
  }

  public String mqttUrl() {
    return (String) document.get("mqtt_url");
  }

  public String mqttsUrl() {
    return (String) document.get("mqtts_url");
  }

  public String caFingerprint() {
    return (String) document.get("ca_fingerprint");
  }

  public String senderUser() {
    return (String) sender().get("username");
  }

  public String senderPassword() {
    return (String) sender().get("password");
  }

  private Map<?, ?> sender() {
    return (Map<?, ?>) document.get("sender");
  }

  /** The sleeve's own account: what the sleeve logs in with to publish its status. */
  public String sleeveUser() {
    return (String) ((Map<?, ?>) document.get("sleeve")).get("username");
  }

  public String sleevePassword() {
    return (String) ((Map<?, ?>) document.get("sleeve")).get("password");
  }

  /** A sender's client to this sleeve over plain MQTT, not yet connected. */
  public SleeveClient.Builder client(String password) {
    return SleeveClient.builder(mqttUrl()).login(senderUser(), password).sleeveId(sleeveId);
  }

  /**
   * Listens to the sleeve as any other sender does, once its retained status has arrived (the
   * subscriptions are then in place and the sleeve is up).
   */
  public Listening listen() throws InterruptedException {
    Listening listening = new Listening();
    listening.client = client(senderPassword()).listener(listening).build();
    listening.client.connect();
    waitFor(() -> listening.statuses.stream().anyMatch(p -> !p.isEmpty()), "status from the sleeve");
    return listening;
  }

  /** The sleeve's events and statuses, heard by a client of their own. */
  public static class Listening implements SleeveClient.Listener, AutoCloseable {
    public final List<SleeveEvent> events = new CopyOnWriteArrayList<>();
    public final List<String> statuses = new CopyOnWriteArrayList<>();
    private SleeveClient client;

    @Override
    public void event(SleeveEvent event) {
      events.add(event);
      heard(event);
    }

    @Override
    public void status(String payload) {
      statuses.add(payload);
      heard(payload);
    }

    /** Each event and status payload as it comes, in order, for a subclass to follow. */
    protected void heard(Object item) {}

    /** How many strokes the sleeve has played (or played adjusted). */
    public long played() {
      return events.stream()
          .filter(e -> SleeveEvent.PLAYED.equals(e.type()) || SleeveEvent.ADJUSTED.equals(e.type()))
          .count();
    }

    @Override
    public void close() {
      if (client != null) {
        client.close();
      }
    }
  }

  /** Waits until {@code condition} holds, failing (AssertionError) after {@link #WAIT_S}. */
  public static void waitFor(BooleanSupplier condition, String what) throws InterruptedException {
    long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(WAIT_S);
    while (!condition.getAsBoolean()) {
      if (System.nanoTime() > deadline) {
        throw new AssertionError("no " + what + " within " + WAIT_S + " s");
      }
      Thread.sleep(20);
    }
  }

  @Override
  public void close() throws InterruptedException {
    if (sleeve != null) {
      stop(sleeve);
    }
    stop(broker);
  }

  private static void stop(Process process) {
    process.destroy(); // SIGTERM: the sleeve stops with every motor off
    try {
      if (!process.waitFor(WAIT_S, TimeUnit.SECONDS)) {
        process.destroyForcibly();
      }
    } catch (InterruptedException interrupted) {
      process.destroyForcibly();
      Thread.currentThread().interrupt();
    }
  }
}
