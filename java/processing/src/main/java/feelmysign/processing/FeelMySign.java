package feelmysign.processing;

import feelmysign.client.SleeveClient;
import feelmysign.client.SleeveEvent;
import feelmysign.client.SleeveFloor;
import feelmysign.client.WearerState;
import feelmysign.json.PyJson;
import feelmysign.protocol.Layout;
import feelmysign.protocol.ParseResult;
import feelmysign.protocol.Protocol;
import feelmysign.protocol.Stroke;
import feelmysign.protocol.StrokeException;
import feelmysign.protocol.WireFormat;
import feelmysign.simplify.Algorithm;
import feelmysign.simplify.Params;
import feelmysign.simplify.Sample;
import feelmysign.simplify.Segment;
import feelmysign.simplify.Simplifier;
import java.lang.reflect.Method;
import java.nio.file.Path;
import java.time.ZoneId;
import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Deque;
import java.util.List;
import java.util.Map;
import java.util.Objects;
import java.util.concurrent.ArrayBlockingQueue;
import java.util.concurrent.BlockingQueue;
import java.util.concurrent.atomic.AtomicLong;
import java.util.concurrent.atomic.AtomicReference;
import processing.core.PApplet;
import processing.event.MouseEvent;

/**
 * feelmysign for a Processing sketch: draw with the mouse, feel it on a sleeve.
 *
 * <pre>
 * import feelmysign.processing.*;
 * FeelMySign sleeve;
 * void setup() {
 *   size(1920, 1080);
 *   sleeve = new FeelMySign(this).broker("mqtt://127.0.0.1:1883").login("sender", "...").start();
 * }
 * void draw() {
 *   background(255);
 *   sleeve.drawSent();   // the strokes sent so far
 *   sleeve.drawLine();   // the line being drawn
 * }
 * </pre>
 *
 * <p>The library registers its own {@code mouseEvent}, {@code draw} and {@code dispose} hooks:
 * a press starts a drawing, each drag goes through the simplifier, each stroke it lets go is
 * sent. A pen held still sends no drag: while it is down and no mouse event has come for {@link
 * #STILL_SAMPLE_MS}, each {@code draw()} samples it where it is, at the events' clock now, so a
 * stroke drawn up to a stop is sent while the pen rests (as the page does). The sleeve's events
 * and the broker's news are queued by the network thread and handed to the sketch on its own
 * thread, at the end of each {@code draw()}: to {@code void
 * sleeveEvent(SleeveEvent event)}, {@code void sleeveStatus(String sentence)} and {@code void
 * sleeveWearer(WearerState wearer)} (the wearer paused the sleeve, set a ceiling, or asked not to
 * be disturbed; also said to {@code sleeveStatus}) when the sketch has them. Nothing the network does throws into {@code draw()}: a broker out of reach, a wrong
 * password or a certificate that does not match is said once, on the console and to {@code
 * sleeveStatus}, and the sketch keeps drawing; strokes drawn meanwhile wait in the client's
 * outbox (or are dropped after {@link #lateLimitMs}, the page's policies). Queues and histories
 * are bounded, so a sketch can draw for hours.
 *
 * <p>The simplifier keeps to the sleeve's floor, as the page does (docs/protocol.md, {@code
 * floor}): the least stroke the sleeve plays as sent (its retained status says it; 73.701 ms on
 * the paper's ERM motors) and, when the sleeve has a wearer file, the shortest stroke its wearer
 * feels. The window simplifier merges a piece briefer than the floor into the next where the
 * error bound allows ({@code floor_ms}); with a wearer's limits it raises {@code min_duration_ms}
 * and {@code min_length} to at least the floor's (a higher setting of the sketch is kept) and
 * never sends a stroke below them ({@code strict_minimums}), and says so once ("At least 118.4 ms
 * and 0.62 grid units per stroke: the sleeve's floor with wearer P01's limits; ..."). A floor
 * that comes while a line is drawn applies from the next line. {@link #params()} is what the
 * simplifier uses, {@link #floor()} the floor it keeps to.
 */
public class FeelMySign {
  /** The library's version, as library.properties' prettyVersion. */
  public static final String VERSION = "0.1.0";
  /** Strokes kept for {@link #drawSent} and {@link #sent}: the oldest go first. */
  public static final int HISTORY_STROKES = 500;
  /** Events waiting for the sketch's next frame; beyond this the oldest are counted, not kept. */
  public static final int EVENT_QUEUE = 1000;
  /** Events kept for {@link #drawPlayed} and {@link #events}. */
  public static final int EVENT_HISTORY = 200;
  /**
   * Samples kept for {@link #drawLine} (about 2.7 minutes of one drag at 60 fps): beyond this the
   * oldest after the press go first, so the line keeps its start and its latest stretch.
   */
  public static final int LINE_SAMPLES = 10_000;
  /**
   * A pen held still on the canvas sends no mouse event. After this long without one (ms, two
   * frames) the library's {@code draw()} hook samples it where it is, and again as often while it
   * stays, as the page does ({@code STILL_SAMPLE_MS}, web/src/ui/pointer.ts): the simplifier sees
   * time pass, so a stroke drawn up to the stop is sent while the pen rests, and the rest is not
   * played as a stroke as long as itself.
   */
  public static final int STILL_SAMPLE_MS = 32;

  private final PApplet parent;
  private String brokerUrl = "mqtt://127.0.0.1:1883";
  private String username;
  private String password;
  private String sleeveId = "sleeve1";
  private WireFormat format = WireFormat.JSON;
  private String legacyTopic;
  private Path caCertificate;
  private String caFingerprint;
  private Long lateLimitMs;
  /** The sketch's own parameters (as configured). */
  private Params params = Params.window();
  /**
   * What the simplifier was made with: the sketch's own, raised to the sleeve's floor (sketch
   * thread writes; volatile, so any thread reading {@link #params()} sees a whole one).
   */
  private volatile Params inUse = params;
  private boolean canvasGiven;

  private SleeveClient client;
  private Simplifier simplifier;
  private LiveFrames frames;
  private boolean started;

  /** Network thread to sketch thread. */
  private final BlockingQueue<Object> inbox = new ArrayBlockingQueue<>(EVENT_QUEUE);
  private final AtomicLong overflowed = new AtomicLong();
  private long overflowTold;
  /** Sentences said since the broker was last connected: each is said once, not per retry. */
  private final java.util.Set<String> said = new java.util.LinkedHashSet<>();
  private final Relay relay = new Relay();
  private String status = "not started";
  private boolean connected;

  private final Deque<Stroke> sent = new ArrayDeque<>();
  private final Deque<SleeveEvent> events = new ArrayDeque<>();
  private final List<Sample> line = new ArrayList<>();
  /**
   * The last sample of the pen down (a mouse event's, or one sampled still), in the mouse events'
   * clock; null while the pen is up (sketch thread).
   */
  private Sample last;
  /**
   * The least of (this JVM's monotonic clock at an event's arrival, ms) minus (the event's {@code
   * getMillis()}) over the line being drawn: the clock of the mouse events now is the monotonic
   * clock less it. Renderers stamp events with their toolkit's time (Java2D AWT's, the OpenGL
   * renderers NEWT's), so the library reads the clock of the events themselves. The least is the
   * event handed over soonest, so the time it gives is never ahead of the events' clock.
   */
  private double eventClockLagMs = Double.POSITIVE_INFINITY;
  private int tooShort;
  private int tooBrief;
  private final Method eventMethod;
  private final Method statusMethod;
  private final Method wearerMethod;
  /** The wearer's choice, from the sleeve's last online status (sketch thread). */
  private WearerState wearer = WearerState.NONE;
  /**
   * The sleeve's floor as the network thread last heard it, until the sketch's next draw()
   * takes it: the latest wins, none is lost to a full {@link #inbox}.
   */
  private final AtomicReference<FloorNews> floorArrived = new AtomicReference<>();
  /** The sleeve's floor the sketch keeps to (sketch thread); null when none is known. */
  private SleeveFloor floor;

  /** The library for {@code parent}; configure it, then {@link #start()} it in setup(). */
  public FeelMySign(PApplet parent) {
    this.parent = parent;
    this.eventMethod = sketchMethod("sleeveEvent", SleeveEvent.class);
    this.statusMethod = sketchMethod("sleeveStatus", String.class);
    this.wearerMethod = sketchMethod("sleeveWearer", WearerState.class);
  }

  // ---- configuration (before start) ----

  /** The broker: mqtt://, mqtts://, ws:// or wss:// (default mqtt://127.0.0.1:1883). */
  public FeelMySign broker(String url) {
    this.brokerUrl = url;
    return this;
  }

  /** User and password (from credentials.json of {@code feelmysign broker}). */
  public FeelMySign login(String user, String pass) {
    // An empty user is no login: a broker that lets anyone in.
    this.username = user == null || user.isEmpty() ? null : user;
    this.password = pass;
    return this;
  }

  /**
   * The sleeve's id (default sleeve1): strokes go to feelmysign/&lt;id&gt;/strokes. An id no
   * sleeve has reported on is said to sleeveStatus a few seconds after connecting, and once
   * more when strokes are sent there ({@link SleeveClient.Listener#noSleeve}).
   */
  public FeelMySign sleeve(String id) {
    this.sleeveId = id;
    return this;
  }

  /** For mqtts:// and wss://: trust the CA of {@code feelmysign up --lan} (its PEM file). */
  public FeelMySign caCertificate(String pemPath) {
    this.caCertificate = Path.of(pemPath);
    return this;
  }

  /** For mqtts:// and wss://: trust the broker's CA by its SHA-256 fingerprint. */
  public FeelMySign caFingerprint(String sha256) {
    this.caFingerprint = sha256;
    return this;
  }

  /** The paper's legacy text on deviceOne/line instead of JSON v1. */
  public FeelMySign legacy() {
    this.format = WireFormat.LEGACY;
    return this;
  }

  /** The legacy text on this topic. */
  public FeelMySign legacy(String topic) {
    this.format = WireFormat.LEGACY;
    this.legacyTopic = topic;
    return this;
  }

  /** Strokes that waited longer than this while offline are dropped, not sent late. */
  public FeelMySign lateLimitMs(long limitMs) {
    this.lateLimitMs = limitMs;
    return this;
  }

  /** The paper's angle simplifier at its appendix B.1 defaults. */
  public FeelMySign angle() {
    return algorithm("angle");
  }

  /** The window simplifier (error-bounded, cut at features) at its defaults. */
  public FeelMySign window() {
    return algorithm("window");
  }

  /** A simplifier by name (angle or window) at its defaults; parameters set before are kept. */
  public FeelMySign algorithm(String name) {
    Algorithm algorithm = Algorithm.named(name);
    Params fresh = algorithm == Algorithm.ANGLE ? Params.angle() : Params.window();
    for (var entry : params.values().entrySet()) {
      if (!entry.getKey().equals("algorithm") && fresh.values().containsKey(entry.getKey())) {
        fresh = fresh.with(entry.getKey(), entry.getValue());
      }
    }
    this.params = fresh;
    return this;
  }

  /**
   * One parameter, by the reference's name ({@code max_error}) or the paper's B.1 name
   * ({@code frameMax}, {@code screenX}, ...). Set after {@link #start()}, it applies from the
   * next line drawn.
   *
   * @throws IllegalArgumentException naming the parameter, the value and the allowed range
   */
  public FeelMySign set(String name, Object value) {
    this.params = params.with(name, value);
    if (name.equals("screenX") || name.equals("screenY") || name.startsWith("canvas_")) {
      canvasGiven = true;
    }
    return this;
  }

  /** Every parameter at once. */
  public FeelMySign params(Params given) {
    this.params = given;
    canvasGiven = true;
    return this;
  }

  /**
   * The simplifier's parameters in use: the sketch's own, kept to the sleeve's floor
   * ({@link #floor()}) from the first line drawn after the sleeve said it. A window simplifier
   * takes the floor's duration as {@code floor_ms}; with a wearer's measured limits, {@code
   * min_duration_ms} and {@code min_length} are raised to at least the floor's (a sketch's higher
   * setting is kept) and {@code strict_minimums} is set (docs/protocol.md, {@code floor}).
   */
  public Params params() {
    return started ? inUse : wanted();
  }

  /**
   * The sleeve's floor the sketch keeps to (its retained status): the least a stroke should be
   * for the sleeve to play it as sent and its wearer to feel it; null before the sleeve said one,
   * or from a sleeve older than it. Kept while the broker or the sleeve is away. Sketch thread.
   */
  public SleeveFloor floor() {
    return floor;
  }

  /**
   * Starts: the canvas is the sketch's (unless set), the client connects (in the background:
   * this returns at once) and the hooks are registered. Call it in setup(), after size().
   */
  public FeelMySign start() {
    if (started) {
      return this;
    }
    if (!canvasGiven) {
      params = params.with("canvas_width_px", parent.width).with("canvas_height_px", parent.height);
    }
    inUse = params;
    simplifier = inUse.algorithm().make(inUse);
    SleeveClient.Builder builder =
        SleeveClient.builder(brokerUrl).sleeveId(sleeveId).format(format).listener(relay);
    if (username != null) {
      builder.login(username, password);
    }
    if (legacyTopic != null) {
      builder.legacyTopic(legacyTopic);
    }
    if (caCertificate != null) {
      builder.caCertificate(caCertificate);
    }
    if (caFingerprint != null) {
      builder.caFingerprint(caFingerprint);
    }
    if (lateLimitMs != null) {
      builder.lateLimitMs(lateLimitMs);
    }
    client = builder.build();
    parent.registerMethod("mouseEvent", this);
    parent.registerMethod("draw", this);
    parent.registerMethod("dispose", this);
    started = true;
    client.connect();
    return this;
  }

  // ---- what a sketch calls ----

  /** Stop: the sleeve stops playing this drawing and drops the rest of it. */
  public void stop() {
    if (client != null) {
      client.stop();
    }
  }

  /**
   * Sends a stroke of your own (grid units, ms) in the current drawing; one the sleeve would
   * refuse (outside the grid, too long) is said on the console and to sleeveStatus instead.
   *
   * @return the stroke as sent, or null when it was not
   */
  public Stroke send(Stroke stroke) {
    requireStarted();
    // Checked as the sleeve will (the paper's "point not in grid", A.3.1): said, not sent.
    Layout layout =
        new Layout(params.rows(), params.columns(), Layout.PAPER.maxStrokeDurationMs());
    if (Protocol.validateStroke(stroke, layout) instanceof ParseResult.Rejected rejected) {
      if (!inbox.offer("a stroke was not sent: " + rejected.message())) {
        overflowed.incrementAndGet();
      }
      return null;
    }
    Stroke out = client.send(stroke);
    remember(out);
    return out;
  }

  /** Sends strokes as one new drawing (e.g. a shape), in order. */
  public void sendDrawing(List<Stroke> strokes) {
    requireStarted();
    client.newDrawing();
    if (params.flag("clear_on_press")) {
      synchronized (sent) {
        sent.clear();
      }
    }
    for (Stroke stroke : strokes) {
      if (send(stroke) == null) {
        return; // said; the rest of the drawing would not make sense without it
      }
    }
  }

  /** Whether the broker is connected now. */
  public boolean connected() {
    return connected;
  }

  /** The broker's news as a sentence (what is wrong and what to do, when something is). */
  public String status() {
    return status;
  }

  /**
   * Strokes the broker has not acknowledged yet (queued while it is out of reach, or awaiting
   * its PUBACK); not those a sleeve that is away has not played: the broker keeps those.
   */
  public int unsent() {
    return client == null ? 0 : client.unsent();
  }

  /** The strokes sent, oldest first (at most {@link #HISTORY_STROKES}); any thread may ask. */
  public List<Stroke> sent() {
    synchronized (sent) {
      return new ArrayList<>(sent);
    }
  }

  /** The sleeve's latest events, oldest first (at most {@link #EVENT_HISTORY}). */
  public List<SleeveEvent> events() {
    synchronized (events) {
      return new ArrayList<>(events);
    }
  }

  /** The canvas x of a grid column (the inverse of the simplifier's mapping). */
  public float canvasX(double gridX) {
    int columns = params.columns();
    double w = params.number("canvas_width_px");
    double h = params.number("canvas_height_px");
    if (columns <= 1) {
      return (float) (w / 2);
    }
    if (params.flag("stretch")) {
      return (float) (gridX * w / (columns - 1));
    }
    double scale = params.mapping().scale();
    double offset = ((columns - 1) - w * scale) / 2;
    return scale == 0 ? (float) (w / 2) : (float) ((gridX - offset) / scale);
  }

  /** The canvas y of a grid row. */
  public float canvasY(double gridY) {
    int rows = params.rows();
    double h = params.number("canvas_height_px");
    if (rows <= 1) {
      return (float) (h / 2);
    }
    if (params.flag("stretch")) {
      return (float) (gridY * h / (rows - 1));
    }
    double scale = params.mapping().scale();
    double offset = ((rows - 1) - h * scale) / 2;
    return scale == 0 ? (float) (h / 2) : (float) ((gridY - offset) / scale);
  }

  /** Draws the strokes sent (the paper's "previously sent vectors") in the current stroke style. */
  public void drawSent() {
    for (Stroke s : sent()) {
      parent.line(canvasX(s.startX()), canvasY(s.startY()), canvasX(s.endX()), canvasY(s.endY()));
    }
  }

  /** Draws the line being drawn, from where the current stroke starts to the pointer. */
  public void drawLine() {
    for (int i = 1; i < line.size(); i++) {
      Sample a = line.get(i - 1);
      Sample b = line.get(i);
      parent.line((float) a.x(), (float) a.y(), (float) b.x(), (float) b.y());
    }
  }

  /**
   * Draws what the sleeve played: each stroke sent (of those kept for {@link #drawSent}) whose
   * {@code played} or {@code adjusted} event arrived. The sleeve's events name a stroke by its
   * drawing and seq only, so the geometry is the library's record of what it sent.
   */
  public void drawPlayed() {
    java.util.Map<String, Stroke> byId = new java.util.HashMap<>();
    for (Stroke s : sent()) {
      if (s.drawing() != null && s.seq() != null) {
        byId.put(strokeId(s.drawing(), s.seq()), s);
      }
    }
    for (SleeveEvent e : events()) {
      if (!(SleeveEvent.PLAYED.equals(e.type()) || SleeveEvent.ADJUSTED.equals(e.type()))
          || e.drawing() == null
          || e.seq() == null) {
        continue;
      }
      // remove: a stroke is drawn once even if its event came twice.
      Stroke s = byId.remove(strokeId(e.drawing(), e.seq()));
      if (s != null) {
        parent.line(canvasX(s.startX()), canvasY(s.startY()), canvasX(s.endX()), canvasY(s.endY()));
      }
    }
  }

  private static String strokeId(String drawing, long seq) {
    return seq + "/" + drawing;
  }

  // ---- the hooks Processing calls (public, for registerMethod) ----

  /** Processing's hook: mouse presses, drags and releases go through the simplifier. */
  public void mouseEvent(MouseEvent event) {
    int action = event.getAction();
    if (action != MouseEvent.PRESS && action != MouseEvent.DRAG && action != MouseEvent.RELEASE) {
      return;
    }
    double x = clamp(event.getX(), params.number("canvas_width_px"));
    double y = clamp(event.getY(), params.number("canvas_height_px"));
    double millis = event.getMillis();
    if (action == MouseEvent.PRESS) {
      eventClockLagMs = Double.POSITIVE_INFINITY; // a new line: the clock is read afresh
    }
    eventClockLagMs = Math.min(eventClockLagMs, monotonicMs() - millis);
    // An event handled after a still sample may be older than it: never back in time.
    double t = action != MouseEvent.PRESS && last != null ? Math.max(millis, last.tMs()) : millis;
    Sample sample = new Sample(t, x, y);
    switch (action) {
      case MouseEvent.PRESS -> press(sample);
      case MouseEvent.DRAG -> move(sample);
      default -> release(sample);
    }
  }

  private static double monotonicMs() {
    return System.nanoTime() / 1e6;
  }

  /**
   * The pen down and no mouse event for {@link #STILL_SAMPLE_MS}: a sample where it is, at the
   * mouse events' clock now (whole ms, as theirs), as the page's still pointer. Fed to the
   * simplifier as a drag is, through the frames for the angle simplifier: the frames of a pause
   * are then taken as it lasts, not when the pen moves again (the page's animation frames do
   * the same), and they are the frames of the same path without the still samples, since each
   * holds the position the pen rests at.
   */
  private void sampleStill() {
    if (!started || last == null || !simplifier.drawing()) {
      return;
    }
    double now = Math.floor(monotonicMs() - eventClockLagMs);
    if (now - last.tMs() < STILL_SAMPLE_MS) {
      return;
    }
    last = new Sample(now, last.x(), last.y(), last.pressure());
    // Not added to the on-screen line: it does not change it.
    feed(inUse.algorithm().takesFrames() ? frames.move(last) : List.of(last));
  }

  private static double clamp(double v, double max) {
    return Math.max(0, Math.min(max, v));
  }

  private void press(Sample sample) {
    if (simplifier.drawing()) {
      release(last != null ? last : sample); // where the pen was last, never back in time
    }
    if (params.flag("clear_on_press")) {
      synchronized (sent) {
        sent.clear();
      }
      synchronized (events) {
        events.clear();
      }
    }
    keepToFloor(); // between paths: a floor that came during the last one applies from here
    client.newDrawing();
    line.clear();
    line.add(sample);
    last = sample;
    if (inUse.algorithm().takesFrames()) {
      frames = new LiveFrames(inUse.fps());
      feed(frames.press(sample));
    } else {
      feed(List.of(sample));
    }
  }

  private void move(Sample sample) {
    if (!simplifier.drawing()) {
      return; // a drag that began outside the sketch
    }
    if (line.size() >= LINE_SAMPLES) {
      line.remove(1); // bounded: the on-screen line of a path drawn for minutes
    }
    line.add(sample);
    last = sample;
    feed(inUse.algorithm().takesFrames() ? frames.move(sample) : List.of(sample));
  }

  private void release(Sample sample) {
    if (!simplifier.drawing()) {
      return;
    }
    move(sample);
    if (inUse.algorithm().takesFrames()) {
      feed(frames.release());
    }
    for (Segment s : simplifier.end()) {
      emit(s);
    }
    line.clear();
    last = null;
    tellDropped();
    keepToFloor(); // a floor that came during this line applies from the next
  }

  /**
   * The paper's NotEnoughDistance and NotEnoughDuration (its B.3.1 and B.3.2): pieces of the
   * line the sleeve could not render leave gaps. Said once per line, with what to tune.
   */
  private void tellDropped() {
    if (tooShort + tooBrief > 0) {
      String sentence = "this line has " + (tooShort + tooBrief) + " gap(s): " + tooShort
          + " piece(s) shorter than minimumSize (" + inUse.number("min_length")
          + " grid units) and " + tooBrief + " briefer than minimumDuration ("
          + inUse.number("min_duration_ms") + " ms) were not sent. Draw larger or slower, "
          + "or tune " + (inUse.algorithm() == Algorithm.ANGLE ? "checkFrame and maxAngleDifDeg"
              : "max_error") + (inUse.values().containsKey("strict_minimums")
                  && inUse.flag("strict_minimums") && floor != null && floor.hasWearer()
              ? " (minimumSize and minimumDuration keep to the wearer " + floor.wearer()
                  + "'s limits: the sleeve's floor)."
              : " (or minimumSize and minimumDuration for your sleeve).");
      if (!inbox.offer(sentence)) {
        overflowed.incrementAndGet();
      }
    }
    tooShort = 0;
    tooBrief = 0;
  }

  private void feed(List<Sample> inputs) {
    for (Sample input : inputs) {
      for (Segment s : simplifier.push(input)) {
        emit(s);
      }
    }
  }

  private void emit(Segment s) {
    if (!s.sent()) {
      if (Segment.NOT_ENOUGH_DISTANCE.equals(s.dropped())) {
        tooShort++;
      } else {
        tooBrief++;
      }
      return;
    }
    Stroke stroke = new Stroke(s.startX(), s.startY(), s.endX(), s.endY(), s.durationMs());
    remember(client.send(stroke));
  }

  private void remember(Stroke stroke) {
    synchronized (sent) {
      if (sent.size() >= HISTORY_STROKES) {
        sent.removeFirst();
      }
      sent.addLast(stroke);
    }
  }

  /**
   * Processing's hook, after the sketch's draw() and the frame's mouse events: a pen held still
   * is sampled where it is ({@link #STILL_SAMPLE_MS}), and the network's news is handed to the
   * sketch, on its own thread.
   */
  public void draw() {
    sampleStill();
    for (Object item; (item = inbox.poll()) != null; ) {
      if (item instanceof SleeveEvent event) {
        synchronized (events) {
          if (events.size() >= EVENT_HISTORY) {
            events.removeFirst();
          }
          events.addLast(event);
        }
        call(eventMethod, event);
      } else if (item instanceof BrokerNews news) {
        connected = news.state == SleeveClient.State.CONNECTED;
        status = news.detail;
        if (connected) {
          said.clear();
        }
        if (said.size() < 50 && said.add(news.detail)) {
          PApplet.println("feelmysign: " + news.detail);
          call(statusMethod, news.detail);
        }
      } else if (item instanceof WearerState state) {
        wearerChanged(state);
      } else if (item instanceof String said) {
        PApplet.println("feelmysign: " + said);
        call(statusMethod, said);
      }
    }
    FloorNews arrived = floorArrived.getAndSet(null);
    if (arrived != null) {
      floorChanged(arrived.floor());
    }
    long lost = overflowed.get();
    if (lost != overflowTold) {
      overflowTold = lost;
      PApplet.println("feelmysign: " + lost + " events came faster than the sketch drew and were not kept");
    }
  }

  /**
   * The wearer's choice changed: said once on the console and to {@code sleeveStatus} (what the
   * wearer chose, or that the sleeve plays again), and handed typed to {@code sleeveWearer}.
   */
  private void wearerChanged(WearerState state) {
    if (state.equals(wearer)) {
      return; // a status republished for another reason
    }
    long nowMs = System.currentTimeMillis();
    boolean wasHeld = wearer.holds(nowMs);
    wearer = state;
    String sentence = state.sentence(nowMs, ZoneId.systemDefault());
    if (sentence == null && wasHeld) {
      sentence = "the wearer resumed the sleeve: strokes play again";
    }
    if (sentence != null) {
      PApplet.println("feelmysign: " + sentence);
      call(statusMethod, sentence);
    }
    call(wearerMethod, state);
  }

  /**
   * The sleeve said another floor (sketch thread): kept to from now when no line is being drawn,
   * else from the next one, never in the middle of a line; said once on the console and to
   * {@code sleeveStatus} when it changes what the simplifier uses.
   */
  private void floorChanged(SleeveFloor now) {
    if (Objects.equals(now, floor)) {
      return;
    }
    Params before = wanted();
    floor = now;
    Params after = wanted();
    if (started && !simplifier.drawing()) {
      keepToFloor();
    }
    if (after.equals(before)) {
      return; // e.g. the motors' floor at the simplifier's own floor_ms: nothing changes
    }
    String sentence = now == null
        ? "The sleeve no longer says a floor: the simplifier keeps to the sketch's own settings"
            + " again."
        : now.note(params);
    if (started && simplifier.drawing()) {
      sentence += " (From the next line drawn.)";
    }
    PApplet.println("feelmysign: " + sentence);
    call(statusMethod, sentence);
  }

  /** The sketch's own parameters kept to the sleeve's floor. */
  private Params wanted() {
    return floor == null ? params : floor.applyTo(params);
  }

  /** Between paths: the simplifier made anew when what it should use has changed. */
  private void keepToFloor() {
    Params want = wanted();
    if (!want.equals(inUse)) {
      inUse = want;
      simplifier = inUse.algorithm().make(inUse);
    }
  }

  /**
   * The wearer's choice (paused, ceiling, "do not disturb") from the sleeve's last online status;
   * {@link WearerState#NONE} before one came, or from an older sleeve. While {@code
   * wearer().holds(millis)} the sleeve refuses every stroke drawn ({@code rejected}, reason
   * {@code paused} or {@code do_not_disturb}).
   */
  public WearerState wearer() {
    return wearer;
  }

  /** Processing's hook when the sketch ends: the client closes (the sleeve is not stopped). */
  public void dispose() {
    if (client != null) {
      client.close();
    }
  }

  private void requireStarted() {
    if (!started) {
      throw new IllegalStateException("feelmysign is not started: call start() in setup() first");
    }
  }

  private Method sketchMethod(String name, Class<?> argument) {
    try {
      return parent.getClass().getMethod(name, argument);
    } catch (NoSuchMethodException absent) {
      return null;
    }
  }

  private void call(Method method, Object argument) {
    if (method == null) {
      return;
    }
    try {
      method.invoke(parent, argument);
    } catch (ReflectiveOperationException error) {
      // The sketch's own callback failed: say so, as Processing does, and keep drawing.
      Throwable cause = error.getCause() == null ? error : error.getCause();
      PApplet.println("feelmysign: " + method.getName() + "() failed: " + cause);
      cause.printStackTrace();
    }
  }

  /** The network thread's side, for tests. */
  SleeveClient.Listener relay() {
    return relay;
  }

  private record BrokerNews(SleeveClient.State state, String detail) {}

  /** The sleeve's floor as heard (null: it says none). */
  private record FloorNews(SleeveFloor floor) {}

  /** What a status says of the sleeve: online, offline, or no sleeve ever listened (cleared). */
  enum SleeveSeen {
    ONLINE,
    OFFLINE,
    NONE;

    /** What {@code payload} says; null for a status not understood. */
    static SleeveSeen of(String payload) {
      if (payload.isBlank()) {
        return NONE;
      }
      try {
        if (PyJson.loads(payload) instanceof Map<?, ?> status
            && status.get("online") instanceof Boolean online) {
          return online ? ONLINE : OFFLINE;
        }
      } catch (RuntimeException notJson) {
        return null;
      }
      return null;
    }
  }

  /** Runs on the network thread (noSleeve may not): only queues, never blocks, never throws. */
  private final class Relay implements SleeveClient.Listener {
    // The sleeve as its last status understood says (null before any): a change is said.
    // Written by the network thread, and by noSleeve from a timer's or the sending thread.
    private volatile SleeveSeen sleeve;

    private void offer(Object item) {
      if (!inbox.offer(item)) {
        overflowed.incrementAndGet();
      }
    }

    @Override
    public void status(String payload) {
      SleeveSeen seen = SleeveSeen.of(payload);
      if (seen == null || seen == sleeve) {
        return;
      }
      SleeveSeen before = sleeve;
      sleeve = seen;
      switch (seen) {
        case OFFLINE ->
            offer(
                "sleeve "
                    + sleeveId
                    + " is offline: no new stroke is felt. Strokes sent now wait at the broker and"
                    + " play if it is back within its age limit (10 s unless set; older ones are"
                    + " refused as stale); if it crashed, a motor it was driving may run until it"
                    + " restarts");
        case NONE -> {
          // Said by the client (noSleeve), which also says it when no status comes at all.
        }
        case ONLINE -> {
          if (before == SleeveSeen.OFFLINE) {
            offer("sleeve " + sleeveId + " is online again");
          } else if (before == SleeveSeen.NONE) {
            offer("sleeve " + sleeveId + " is online: strokes sent from now on are felt");
          }
        }
      }
    }

    @Override
    public void noSleeve(String sentence) {
      sleeve = SleeveSeen.NONE;
      offer(sentence);
    }

    @Override
    public void broker(SleeveClient.State state, String detail) {
      offer(new BrokerNews(state, detail == null ? state.toString().toLowerCase() : detail));
    }

    @Override
    public void event(SleeveEvent event) {
      offer(event);
    }

    @Override
    public void wearer(WearerState state) {
      offer(state);
    }

    @Override
    public void floor(SleeveFloor floor) {
      floorArrived.set(new FloorNews(floor));
    }

    @Override
    public void floorIgnored(String sentence) {
      offer(sentence);
    }

    @Override
    public void refused(Stroke stroke, StrokeException error) {
      offer("a stroke was not sent: " + error.getMessage());
    }

    @Override
    public void late(List<Stroke> strokes) {
      offer(strokes.size() + " strokes waited too long while offline and were dropped");
    }
  }
}
