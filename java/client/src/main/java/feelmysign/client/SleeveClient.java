package feelmysign.client;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.MqttClientSslConfig;
import com.hivemq.client.mqtt.MqttGlobalPublishFilter;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.lifecycle.MqttClientDisconnectedContext;
import com.hivemq.client.mqtt.lifecycle.MqttDisconnectSource;
import com.hivemq.client.mqtt.mqtt3.Mqtt3AsyncClient;
import com.hivemq.client.mqtt.mqtt3.Mqtt3ClientBuilder;
import com.hivemq.client.mqtt.mqtt3.exceptions.Mqtt3ConnAckException;
import com.hivemq.client.mqtt.mqtt3.message.connect.connack.Mqtt3ConnAckReturnCode;
import com.hivemq.client.mqtt.mqtt3.message.publish.Mqtt3Publish;
import feelmysign.json.JsonDecodeException;
import feelmysign.json.NonFiniteLiteralException;
import feelmysign.json.PyDumps;
import feelmysign.json.PyJson;
import feelmysign.protocol.Control;
import feelmysign.protocol.Protocol;
import feelmysign.protocol.Stroke;
import feelmysign.protocol.StrokeException;
import feelmysign.protocol.Topics;
import feelmysign.protocol.WireFormat;
import java.io.IOException;
import java.io.InputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.GeneralSecurityException;
import java.security.KeyStore;
import java.security.cert.Certificate;
import java.security.cert.CertificateFactory;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.UUID;
import java.util.concurrent.ThreadLocalRandom;
import java.util.concurrent.TimeUnit;
import javax.net.ssl.TrustManagerFactory;

/**
 * Sends strokes to one sleeve and hears back from it, as the drawing page does
 * ({@code web/src/mqtt/sender.ts}): MQTT 3.1.1, strokes at QoS 1 on
 * {@code feelmysign/<sleeve>/strokes} (JSON v1, with the drawing's id, {@code seq} counted from
 * 0 and {@code sent_at_ms} stamped when it is made, kept while it waits for the broker, so the
 * sleeve's pace rules judge a stroke held offline by when it was drawn) or on the legacy topic (the
 * paper's text),
 * Stop as the cancel message, the sleeve's {@code status} and {@code events} as callbacks, and
 * the floor its status advertises ({@link #floor()}: the least stroke it plays as sent and its
 * wearer feels; a sender's simplifier keeps to it, {@link SleeveFloor#applyTo}).
 *
 * <p>Strokes wait in an outbox while the broker is out of reach and go out, in order, when it is
 * back; one leaves the outbox only on the broker's PUBACK, so {@link #unsent()} is honest. With
 * a late limit, strokes that waited longer are dropped instead and reported
 * ({@link Listener#late}). The connection is retried every 2 s, except after a refused login,
 * which retrying cannot fix. Callbacks come from the network thread; they must not block.
 *
 * <pre>
 * SleeveClient client = SleeveClient.builder("mqtt://127.0.0.1:1883")
 *     .login("sender", password).sleeveId("sleeve1").listener(listener).build();
 * client.connect();
 * client.newDrawing();
 * client.send(new Stroke(0, 0, 2, 0, 500));
 * client.stop();   // cancel the drawing on the sleeve
 * </pre>
 */
public final class SleeveClient implements AutoCloseable {
  /** How long to wait between reconnection attempts (the page's). */
  public static final long RECONNECT_PERIOD_MS = 2000;
  /** The broker notices a vanished sender after 1.5 x this. */
  public static final int KEEPALIVE_S = 20;
  /**
   * A sleeve that ever reported has its retained status at the broker, sent right after the
   * subscription: none within this, none listens (the page's STATUS_WAIT_MS, the Python CLI's
   * STATUS_WAIT_S).
   */
  public static final long STATUS_WAIT_MS = 2500;

  /** The connection to the broker. */
  public enum State {
    CONNECTING,
    CONNECTED,
    OFFLINE
  }

  /** What the client tells; every method has a default that does nothing. */
  public interface Listener {
    /** The connection changed, with a sentence to show (what is wrong and what to do). */
    default void broker(State state, String detail) {}

    /** The sleeve's retained status (JSON; "" when it was cleared). */
    default void status(String payload) {}

    /**
     * No sleeve listens on the id ({@link #noSleeveSentence}): the broker holds no status of it,
     * none having come within {@link #STATUS_WAIT_MS} of subscribing, or it was cleared. Said
     * once per connection, and once more when strokes are sent after it was said (not per
     * stroke; strokes sent while it was found out are covered by the first). Not with the legacy
     * format, whose topic any sleeve may read. From the network thread, a timer's, or the thread
     * that sent the stroke. By default the sentence is printed on the console (System.err).
     */
    default void noSleeve(String sentence) {
      System.err.println("feelmysign: " + sentence);
    }

    /**
     * The wearer's choice (paused, ceiling, "do not disturb"), typed, right after each online
     * {@link #status} that carries it or none ({@link WearerState#NONE}: an older sleeve). Not
     * after an offline status: the last will carries no controls, and the wearer's choice is kept
     * on the sleeve. A status whose {@code controls} is not understood is not passed on.
     */
    default void wearer(WearerState state) {}

    /**
     * The sleeve's floor changed ({@link SleeveClient#floor()}): right after the {@link #status}
     * that says it; null when an online status says none (a sleeve older than it). Not called
     * for a status that keeps it (see {@link SleeveClient#floor()}).
     */
    default void floor(SleeveFloor floor) {}

    /**
     * A status's {@code floor} is not understood and was ignored (the floor known before is
     * kept), with a sentence saying why; once per such floor, not per republished status. By
     * default the sentence is printed on the console (System.err).
     */
    default void floorIgnored(String sentence) {
      System.err.println("feelmysign: " + sentence);
    }

    /** One event of the sleeve: played, adjusted, rejected, cancelled, safety, error. */
    default void event(SleeveEvent event) {}

    /** The broker acknowledged this stroke (PUBACK). */
    default void acked(Stroke stroke) {}

    /** A stroke that cannot be sent (outside what any sleeve accepts): never silently dropped. */
    default void refused(Stroke stroke, StrokeException error) {}

    /** Strokes that waited longer than the late limit and were dropped. */
    default void late(List<Stroke> strokes) {}

    /** How many strokes the sleeve may not have yet (queued or awaiting PUBACK). */
    default void unsent(int count) {}
  }

  private final BrokerUrl url;
  private final String username;
  private final String password;
  private final String sleeveId;
  private final WireFormat format;
  private final String legacyTopic;
  private final Path caCertificate;
  private final String caFingerprint;
  private final Long lateLimitMs;
  private final Listener listener;

  private final Object lock = new Object();
  /** Held while a flush takes and publishes, so two threads' flushes never interleave. */
  private final Object flushLock = new Object();
  private final Outbox<Stroke> outbox = new Outbox<>();
  /** Cancels not yet acknowledged, sent before any stroke when the broker is back. */
  private final List<String> cancels = new ArrayList<>();
  private Mqtt3AsyncClient client;
  private boolean connected;
  private boolean loginRefused;
  private String lastCertificateProblem;
  /** Whether the broker being out of reach has been told since the last connection. */
  private boolean outageTold;
  private String drawing;
  private long nextSeq;
  /** The sleeve's last known floor (network thread writes, any thread reads). */
  private volatile SleeveFloor floor;
  /** The last floor not understood, told once (network thread only). */
  private String floorIgnoredTold;
  /** Counts connections and losses: a status wait of an earlier connection does nothing. */
  private long connection;
  /** Whether a sleeve listens: null while its retained status is awaited, or not connected. */
  private Boolean sleeveListens;
  /** Whether strokes sent to the id no sleeve listens on have been told (once, not per stroke). */
  private boolean absenceToldForStrokes;
  /** Whether strokes were sent while it was not known whether a sleeve listens. */
  private boolean sentWhileUnknown;

  private SleeveClient(Builder b) {
    this.url = b.url;
    this.username = b.username;
    this.password = b.password;
    this.sleeveId = b.sleeveId;
    this.format = b.format;
    this.legacyTopic = b.legacyTopic;
    this.caCertificate = b.caCertificate;
    this.caFingerprint = b.caFingerprint;
    this.lateLimitMs = b.lateLimitMs;
    this.listener = b.listener;
  }

  /** A client for the broker at {@code brokerUrl} (mqtt://, mqtts://, ws:// or wss://). */
  public static Builder builder(String brokerUrl) {
    return new Builder(BrokerUrl.parse(brokerUrl));
  }

  /** How to reach the broker and the sleeve. */
  public static final class Builder {
    private final BrokerUrl url;
    private String username;
    private String password;
    private String sleeveId = "sleeve1";
    private WireFormat format = WireFormat.JSON;
    private String legacyTopic = Topics.LEGACY_TOPIC;
    private Path caCertificate;
    private String caFingerprint;
    private Long lateLimitMs;
    private Listener listener = new Listener() {};

    private Builder(BrokerUrl url) {
      this.url = url;
    }

    public Builder login(String user, String pass) {
      this.username = user;
      this.password = pass;
      return this;
    }

    /** The sleeve's id: 1-64 letters, digits, '_' or '-' (default sleeve1). */
    public Builder sleeveId(String id) {
      if (id == null || !id.matches("[A-Za-z0-9_-]{1,64}")) {
        throw new IllegalArgumentException(
            "sleeve id " + id + " must be 1-64 letters, digits, '_' or '-' (e.g. sleeve1)");
      }
      this.sleeveId = id;
      return this;
    }

    /** JSON v1 on the sleeve's strokes topic (default), or the paper's legacy text. */
    public Builder format(WireFormat wireFormat) {
      this.format = wireFormat;
      return this;
    }

    /** Where legacy text goes (default deviceOne/line, the paper's). */
    public Builder legacyTopic(String topic) {
      this.legacyTopic = topic;
      return this;
    }

    /** The CA to trust for mqtts:// and wss:// (PEM; e.g. the one of feelmysign up --lan). */
    public Builder caCertificate(Path pem) {
      this.caCertificate = pem;
      return this;
    }

    /**
     * Trust the CA whose SHA-256 fingerprint this is (64 hex digits: a join token's, or
     * credentials.json's ca_fingerprint), taken from the broker's own chain.
     */
    public Builder caFingerprint(String sha256) {
      new PinnedCa(sha256); // checked now: a typo is told at once
      this.caFingerprint = sha256;
      return this;
    }

    /** Strokes not sent within this many ms are dropped (null: sent whenever possible). */
    public Builder lateLimitMs(Long limitMs) {
      this.lateLimitMs = limitMs;
      return this;
    }

    public Builder listener(Listener value) {
      this.listener = value;
      return this;
    }

    public SleeveClient build() {
      return new SleeveClient(this);
    }
  }

  /** Connects (and keeps reconnecting) in the background; returns at once. */
  public void connect() {
    Mqtt3ClientBuilder builder =
        MqttClient.builder()
            .useMqttVersion3()
            .identifier(
                "feelmysign-java-" + Long.toHexString(ThreadLocalRandom.current().nextLong()))
            .serverHost(url.host())
            .serverPort(url.port())
            .automaticReconnect()
            .initialDelay(RECONNECT_PERIOD_MS, TimeUnit.MILLISECONDS)
            .maxDelay(RECONNECT_PERIOD_MS, TimeUnit.MILLISECONDS)
            .applyAutomaticReconnect()
            .addConnectedListener(context -> onConnected())
            .addDisconnectedListener(this::onDisconnected);
    if (url.tls()) {
      builder = builder.sslConfig(sslConfig());
    }
    if (url.webSocket()) {
      String path = url.path().startsWith("/") ? url.path().substring(1) : url.path();
      builder = builder.webSocketConfig().serverPath(path).applyWebSocketConfig();
    }
    Mqtt3AsyncClient created = builder.buildAsync();
    synchronized (lock) {
      client = created;
      connected = false;
      loginRefused = false;
      outbox.requeueInFlight();
    }
    created.publishes(MqttGlobalPublishFilter.SUBSCRIBED, this::onMessage);
    listener.broker(State.CONNECTING, "Connecting to " + url + "...");
    var connect = created.connectWith().cleanSession(true).keepAlive(KEEPALIVE_S);
    if (username != null) {
      connect
          .simpleAuth()
          .username(username)
          .password(password == null ? new byte[0] : password.getBytes(StandardCharsets.UTF_8))
          .applySimpleAuth();
    }
    // A failure is told by the disconnected listener, which also retries.
    connect.send();
  }

  private MqttClientSslConfig sslConfig() {
    if (caFingerprint != null) {
      return MqttClientSslConfig.builder().trustManagerFactory(new PinnedCa(caFingerprint)).build();
    }
    if (caCertificate == null) {
      return MqttClientSslConfig.builder().build(); // the JVM's trusted CAs
    }
    try (InputStream in = Files.newInputStream(caCertificate)) {
      KeyStore store = KeyStore.getInstance(KeyStore.getDefaultType());
      store.load(null, null);
      int index = 0;
      for (Certificate certificate : CertificateFactory.getInstance("X.509").generateCertificates(in)) {
        store.setCertificateEntry("ca-" + index++, certificate);
      }
      if (index == 0) {
        throw new IllegalArgumentException(
            caCertificate + " holds no certificate; give the CA's PEM file (ca.pem)");
      }
      TrustManagerFactory trust =
          TrustManagerFactory.getInstance(TrustManagerFactory.getDefaultAlgorithm());
      trust.init(store);
      return MqttClientSslConfig.builder().trustManagerFactory(trust).build();
    } catch (IOException | GeneralSecurityException error) {
      throw new IllegalArgumentException(
          "cannot read the CA certificate " + caCertificate + ": " + error.getMessage(), error);
    }
  }

  private void onConnected() {
    Mqtt3AsyncClient current;
    long thisConnection;
    synchronized (lock) {
      current = client;
      connected = true;
      lastCertificateProblem = null;
      outageTold = false;
      thisConnection = ++connection;
      sleeveListens = null;
      absenceToldForStrokes = false;
    }
    listener.broker(
        State.CONNECTED,
        "Connected to " + url + " as " + (username == null ? "anonymous" : username));
    for (String name : List.of(Topics.STATUS, Topics.EVENTS)) {
      current
          .subscribeWith()
          .topicFilter(Topics.telemetryTopic(sleeveId, name))
          .qos(MqttQos.AT_MOST_ONCE)
          .send()
          .whenComplete(
              (ack, error) -> {
                if (error != null) {
                  listener.broker(
                      State.CONNECTED,
                      "Connected, but cannot read the sleeve's " + name + ": " + error.getMessage());
                } else if (name.equals(Topics.STATUS)) {
                  // The retained status, if the broker holds one, follows the SUBACK at once.
                  java.util.concurrent.CompletableFuture.runAsync(
                      () -> statusAwaited(thisConnection),
                      java.util.concurrent.CompletableFuture.delayedExecutor(
                          STATUS_WAIT_MS, TimeUnit.MILLISECONDS));
                }
              });
    }
    flush();
  }

  private void onDisconnected(MqttClientDisconnectedContext context) {
    Throwable cause = context.getCause();
    boolean wasConnected;
    synchronized (lock) {
      wasConnected = connected;
      connected = false;
      outbox.requeueInFlight();
      connection++;
      sleeveListens = null;
    }
    if (context.getSource() == MqttDisconnectSource.USER) {
      context.getReconnector().reconnect(false);
      return;
    }
    if (cause instanceof Mqtt3ConnAckException refused) {
      Mqtt3ConnAckReturnCode code = refused.getMqttMessage().getReturnCode();
      if (code == Mqtt3ConnAckReturnCode.BAD_USER_NAME_OR_PASSWORD
          || code == Mqtt3ConnAckReturnCode.NOT_AUTHORIZED) {
        // Retrying a refused login only fills the broker's log: stop until it is fixed.
        context.getReconnector().reconnect(false);
        synchronized (lock) {
          loginRefused = true;
        }
        listener.broker(
            State.OFFLINE,
            "The broker at "
                + url
                + (username == null
                    ? " refused a login without a user name ("
                    : " refused the login of '" + username + "' (")
                + code
                + "). Give the sender's username and password from the credentials.json that"
                + " 'feelmysign broker' writes in its state directory.");
        return;
      }
    }
    context.getReconnector().reconnect(true);
    String certificate = certificateProblem(cause);
    if (certificate != null) {
      synchronized (lock) {
        if (certificate.equals(lastCertificateProblem)) {
          return; // told once; still retrying
        }
        lastCertificateProblem = certificate;
      }
      listener.broker(
          State.OFFLINE,
          "The broker at "
              + url
              + " has a certificate this client does not trust ("
              + certificate
              + "); retrying every "
              + RECONNECT_PERIOD_MS / 1000
              + " s. Give the broker's CA (caCertificate) or its fingerprint (caFingerprint).");
      return;
    }
    // Told once per outage, not per retry. (HiveMQ counts the first attempt as 1, so its
    // attempt count cannot say which failure is the first.)
    boolean tell;
    synchronized (lock) {
      tell = wasConnected || !outageTold;
      outageTold = true;
    }
    if (tell) {
      listener.broker(
          State.OFFLINE,
          ConnectFailure.sentence(url, cause)
              + " Retrying every "
              + RECONNECT_PERIOD_MS / 1000
              + " s.");
    }
  }

  /** The certificate error in a failed connection's causes, or null. */
  private static String certificateProblem(Throwable cause) {
    for (Throwable t = cause; t != null; t = t.getCause()) {
      if (t instanceof java.security.cert.CertificateException
          || t instanceof javax.net.ssl.SSLHandshakeException) {
        Throwable root = t;
        while (root.getCause() != null) {
          root = root.getCause();
        }
        return String.valueOf(root.getMessage());
      }
    }
    return null;
  }

  private void onMessage(Mqtt3Publish publish) {
    String topic = publish.getTopic().toString();
    String text = new String(publish.getPayloadAsBytes(), StandardCharsets.UTF_8);
    if (topic.equals(Topics.telemetryTopic(sleeveId, Topics.STATUS))) {
      boolean floorChanged = readFloor(text);
      boolean absent = text.isBlank();
      boolean tell;
      synchronized (lock) {
        tell = absent && !Boolean.FALSE.equals(sleeveListens) && format != WireFormat.LEGACY;
        sleeveListens = !absent;
        absenceToldForStrokes = false;
        sentWhileUnknown = false;
      }
      listener.status(text);
      if (tell) {
        listener.noSleeve(noSleeveSentence(sleeveId));
      }
      if (floorChanged) {
        listener.floor(floor);
      }
      WearerState wearer = onlineWearer(text);
      if (wearer != null) {
        listener.wearer(wearer);
      }
    } else if (topic.equals(Topics.telemetryTopic(sleeveId, Topics.EVENTS))) {
      SleeveEvent event = SleeveEvent.parse(text);
      if (event != null) {
        listener.event(event);
      }
    }
  }

  /**
   * The wait for the retained status of connection {@code which} is over: with none, no sleeve
   * listens, and that is said (the strokes sent so far are covered by it).
   */
  private void statusAwaited(long which) {
    synchronized (lock) {
      if (which != connection || !connected || sleeveListens != null) {
        return;
      }
      sleeveListens = false;
      absenceToldForStrokes = sentWhileUnknown;
      sentWhileUnknown = false;
    }
    if (format != WireFormat.LEGACY) {
      listener.noSleeve(noSleeveSentence(sleeveId));
    }
  }

  /**
   * What {@link Listener#noSleeve} says: the page's words (web/src/sleeve-state.ts), for a sender
   * without its settings.
   */
  public static String noSleeveSentence(String sleeveId) {
    return "no sleeve listens on id '"
        + sleeveId
        + "': nothing has ever reported there, so strokes sent now are not felt; check the"
        + " sleeve id (a sleeve prints its id when it starts)";
  }

  /**
   * Updates {@link #floor} from a status payload, as the page keeps it (web/src/sleeve-state.ts):
   * an online status sets it (to none when it has no floor: an older sleeve); an offline one
   * (the last will) sets it only when it says one; a cleared status, one not understood, or a
   * floor not understood keeps the floor known before. Whether it changed.
   */
  private boolean readFloor(String payload) {
    Map<?, ?> status;
    try {
      if (!(PyJson.loads(payload) instanceof Map<?, ?> map) || !(map.get("online") instanceof Boolean)) {
        return false;
      }
      status = map;
    } catch (JsonDecodeException | NonFiniteLiteralException error) {
      return false;
    }
    SleeveFloor now;
    SleeveFloor.Read read = SleeveFloor.read(status.get("floor"));
    if (read instanceof SleeveFloor.Said said) {
      now = said.floor();
    } else if (read instanceof SleeveFloor.NotUnderstood bad) {
      String text = PyDumps.dumps(status.get("floor"));
      if (!text.equals(floorIgnoredTold)) {
        floorIgnoredTold = text;
        listener.floorIgnored(
            "the sleeve's floor in its status is not understood and was ignored ("
                + bad.problem()
                + (floor == null
                    ? "): none is kept to"
                    : "): the floor it said before is kept")
                + ". Its status said \"floor\": "
                + (text.length() > 200 ? text.substring(0, 200) + "..." : text));
      }
      return false;
    } else {
      if (!Boolean.TRUE.equals(status.get("online"))) {
        return false; // a last will without a floor: the sleeve's floor has not changed
      }
      now = null;
    }
    floorIgnoredTold = null;
    if (java.util.Objects.equals(now, floor)) {
      return false;
    }
    floor = now;
    return true;
  }

  /**
   * The sleeve's last known floor (its retained status, {@code floor}): the least a stroke should
   * be for this sleeve to play it as sent and its wearer to feel it; null when none is known (no
   * status yet, or a sleeve older than it). Kept while the broker is out of reach and through the
   * sleeve's last will: a sleeve's floor does not change because it or the network went away.
   * Any thread may ask.
   */
  public SleeveFloor floor() {
    return floor;
  }

  /** The wearer's state in an online status; null for an offline one or one not understood. */
  public static WearerState onlineWearer(String statusPayload) {
    try {
      if (!(PyJson.loads(statusPayload) instanceof Map<?, ?> status)
          || !Boolean.TRUE.equals(status.get("online"))) {
        return null;
      }
    } catch (JsonDecodeException | NonFiniteLiteralException error) {
      return null;
    }
    return WearerState.parse(statusPayload);
  }

  /** Starts a new drawing: a new id (a random UUID), its strokes counted from 0. */
  public String newDrawing() {
    synchronized (lock) {
      drawing = UUID.randomUUID().toString();
      nextSeq = 0;
      return drawing;
    }
  }

  /** The drawing strokes are sent in (null before {@link #newDrawing}). */
  public String drawing() {
    synchronized (lock) {
      return drawing;
    }
  }

  /**
   * Queues a stroke and sends it now if the broker is connected. A stroke without a drawing
   * becomes the next of the current one (a drawing is started if there is none).
   *
   * @return the stroke as it is sent (its drawing and seq)
   */
  public Stroke send(Stroke stroke) {
    Stroke addressed;
    boolean tellAbsence;
    synchronized (lock) {
      if (stroke.drawing() == null) {
        if (drawing == null) {
          newDrawing();
        }
        addressed = stroke.inDrawing(drawing, nextSeq++, 0).withSentAt(null);
      } else {
        addressed = stroke;
      }
      if (addressed.sentAtMs() == null) {
        // Stamped now, when it is made: kept through an outage and any sending again.
        addressed = addressed.withSentAt((double) System.currentTimeMillis());
      }
      outbox.add(addressed, nowMs());
      tellAbsence = Boolean.FALSE.equals(sleeveListens) && !absenceToldForStrokes;
      if (tellAbsence) {
        absenceToldForStrokes = true;
      }
      if (sleeveListens == null) {
        sentWhileUnknown = true;
      }
    }
    if (tellAbsence && format != WireFormat.LEGACY) {
      listener.noSleeve(noSleeveSentence(sleeveId));
    }
    flush();
    return addressed;
  }

  /**
   * Stop: cancels the current drawing on the sleeve (its strokes still here are dropped, the
   * sleeve stops playing and drops the rest). Returns how many unsent strokes were dropped.
   */
  public int stop() {
    String current = drawing();
    return current == null ? 0 : cancel(current);
  }

  /** Cancels a drawing, or everything with {@link Control#CANCEL_ALL}. */
  public int cancel(String drawingId) {
    List<Stroke> dropped;
    synchronized (lock) {
      dropped =
          outbox.dropQueued(
              (stroke, entry) ->
                  drawingId.equals(Control.CANCEL_ALL) || drawingId.equals(stroke.drawing()));
      cancels.remove(drawingId);
      cancels.add(drawingId);
    }
    flush();
    return dropped.size();
  }

  /** Queued plus awaiting PUBACK: every stroke the sleeve may not have yet. */
  public int unsent() {
    synchronized (lock) {
      return outbox.size();
    }
  }

  /** Whether the broker connection is up. */
  public boolean connected() {
    synchronized (lock) {
      return connected;
    }
  }

  /** Whether the broker refused the login (the client stopped retrying). */
  public boolean loginRefused() {
    synchronized (lock) {
      return loginRefused;
    }
  }

  private static long nowMs() {
    return System.nanoTime() / 1_000_000;
  }

  private void flush() {
    // The sketch's thread (send, stop) and the network thread (a new connection) both flush;
    // one at a time, so strokes go out in the order they were drawn.
    synchronized (flushLock) {
      flushInOrder();
    }
  }

  private void flushInOrder() {
    List<Stroke> late = List.of();
    List<Runnable> publishes = new ArrayList<>();
    int unsent;
    synchronized (lock) {
      Mqtt3AsyncClient current = client;
      if (current != null && connected) {
        if (lateLimitMs != null) {
          long now = nowMs();
          late = outbox.dropQueued((stroke, entry) -> now - entry.addedMs() > lateLimitMs);
        }
        for (String cancel : List.copyOf(cancels)) {
          byte[] payload =
              Control.formatControl(new Control.Cancel(cancel)).getBytes(StandardCharsets.UTF_8);
          publishes.add(
              () ->
                  publish(current, Topics.controlTopic(sleeveId), payload)
                      .whenComplete(
                          (ack, error) -> {
                            if (error == null) {
                              synchronized (lock) {
                                if (client == current) {
                                  cancels.remove(cancel);
                                }
                              }
                            }
                          }));
        }
        for (Outbox.Entry<Stroke> entry : outbox.takeQueued()) {
          Stroke stroke = entry.item();
          String topic;
          String text;
          try {
            if (format == WireFormat.LEGACY) {
              topic = legacyTopic;
              text = Protocol.formatLegacy(stroke);
            } else {
              topic = Topics.strokesTopic(sleeveId);
              text = Protocol.formatJson(stroke);
            }
          } catch (StrokeException error) {
            outbox.ack(entry.id());
            publishes.add(() -> listener.refused(stroke, error));
            continue;
          }
          byte[] payload = text.getBytes(StandardCharsets.UTF_8);
          publishes.add(
              () ->
                  publish(current, topic, payload)
                      .whenComplete(
                          (ack, error) -> {
                            int left;
                            synchronized (lock) {
                              // A replaced connection's late answers must not touch the new one's.
                              if (client != current) {
                                return;
                              }
                              if (error != null) {
                                outbox.fail(entry.id());
                              } else {
                                outbox.ack(entry.id());
                              }
                              left = outbox.size();
                            }
                            if (error == null) {
                              listener.acked(stroke);
                            }
                            listener.unsent(left);
                          }));
        }
      }
      unsent = outbox.size();
    }
    if (!late.isEmpty()) {
      listener.late(late);
    }
    // Published outside the lock, in order: cancels first, then the strokes.
    publishes.forEach(Runnable::run);
    listener.unsent(unsent);
  }

  private static java.util.concurrent.CompletableFuture<?> publish(
      Mqtt3AsyncClient client, String topic, byte[] payload) {
    return client
        .publishWith()
        .topic(topic)
        .qos(MqttQos.AT_LEAST_ONCE)
        .payload(payload)
        .send();
  }

  /** Disconnects; strokes not yet acknowledged stay counted in {@link #unsent()}. */
  @Override
  public void close() {
    Mqtt3AsyncClient current;
    synchronized (lock) {
      current = client;
      client = null;
      connected = false;
    }
    if (current != null) {
      try {
        current.disconnect().get(5, TimeUnit.SECONDS);
      } catch (Exception notConnected) {
        // Not connected, or already gone: nothing to close.
      }
    }
  }
}
