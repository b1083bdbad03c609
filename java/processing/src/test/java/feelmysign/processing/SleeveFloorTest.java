package feelmysign.processing;

import static feelmysign.testing.LiveSleeve.waitFor;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertSame;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.hivemq.client.mqtt.MqttClient;
import com.hivemq.client.mqtt.datatypes.MqttQos;
import com.hivemq.client.mqtt.mqtt3.Mqtt3BlockingClient;
import feelmysign.client.SleeveEvent;
import feelmysign.client.SleeveFloor;
import feelmysign.protocol.Stroke;
import feelmysign.simplify.Params;
import feelmysign.testing.LiveSleeve;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;
import processing.core.PConstants;
import processing.event.MouseEvent;

/**
 * The library keeps to the sleeve's floor (docs/protocol.md, {@code floor}): the sleeve's
 * retained status, through a real Mosquitto started by {@code feelmysign broker}, reaches the
 * simplifier's parameters between lines, and the strokes of a line drawn after it are at or above
 * a wearer's limits. The sketch is not run: its hooks are called as Processing calls them, on
 * this thread (the sketch's).
 */
class SleeveFloorTest {
  private static final double P01_MS = 118.4;
  private static final double P01_LENGTH = 0.62;
  private static final String P01_FLOOR =
      "{\"min_duration_ms\": 118.4, \"min_length\": 0.62, \"wearer\": \"P01\"}";

  private static void post(FeelMySign library, int action, long millis, int x, int y) {
    library.mouseEvent(new MouseEvent(null, millis, action, 0, x, y, PConstants.LEFT, 1));
  }

  /**
   * A quick zigzag from {@code t0}: ten legs of 0.46 grid units (on a 1920 x 1080 canvas), 64 ms
   * each, turning sharply at every corner; the pen stays down unless {@code release}.
   */
  private static long zigzag(FeelMySign library, long t0, boolean release) {
    long t = t0;
    int x = 200;
    int y = 300;
    post(library, MouseEvent.PRESS, t, x, y);
    for (int leg = 0; leg < 10; leg++) {
      int toX = x + 150;
      int toY = leg % 2 == 0 ? 550 : 300;
      for (int k = 1; k <= 4; k++) {
        t += 16;
        post(library, MouseEvent.DRAG, t, x + (toX - x) * k / 4, y + (toY - y) * k / 4);
      }
      x = toX;
      y = toY;
    }
    if (release) {
      post(library, MouseEvent.RELEASE, t, x, y);
    }
    return t + 1000;
  }

  private static double length(Stroke s) {
    return Math.hypot(s.endX() - s.startX(), s.endY() - s.startY());
  }

  private static boolean belowP01(Stroke s) {
    return s.durationMs() < P01_MS || length(s) < P01_LENGTH;
  }

  private static FeelMySignTest.Sketch sketch() {
    FeelMySignTest.Sketch sketch = new FeelMySignTest.Sketch();
    sketch.width = 1920;
    sketch.height = 1080;
    return sketch;
  }

  private static void drawUntil(FeelMySign library, java.util.function.BooleanSupplier done,
      String what) throws InterruptedException {
    waitFor(() -> {
      library.draw(); // Processing's hook, on this (the sketch's) thread
      return done.getAsBoolean();
    }, what);
  }

  @Test
  void theRealSleevesFloorWithItsWearerKeepsEveryStrokeAtOrAboveTheWearersLimits(
      @TempDir Path state) throws Exception {
    Path wearer = state.resolve("p01.json");
    Files.writeString(wearer,
        "{\"wearer\": \"P01\", \"min_length\": 0.62, \"min_duration_ms\": 118.4}\n");
    try (LiveSleeve live =
            LiveSleeve.start(state, "java-floor-sleeve", List.of(),
                List.of("--wearer", wearer.toString()));
        LiveSleeve.Listening heard = live.listen()) {
      FeelMySignTest.Sketch sketch = sketch();
      FeelMySign library = new FeelMySign(sketch).broker(live.mqttUrl())
          .login(live.senderUser(), live.senderPassword()).sleeve(live.sleeveId()).start();
      try {
        drawUntil(library, () -> library.floor() != null, "the sleeve's floor");
        assertEquals(new SleeveFloor(P01_MS, P01_LENGTH, "P01"), library.floor());
        Params used = library.params();
        assertEquals(P01_MS, used.number("floor_ms"));
        assertEquals(P01_MS, used.number("min_duration_ms"));
        assertEquals(P01_LENGTH, used.number("min_length"));
        assertTrue(used.flag("strict_minimums"));
        assertTrue(sketch.statuses.contains("At least 118.4 ms and 0.62 grid units per stroke:"
            + " the sleeve's floor with wearer P01's limits; min duration and min length raised"
            + " to it."), sketch.statuses.toString());

        zigzag(library, 0, true);
        List<Stroke> sent = library.sent();
        assertFalse(sent.isEmpty(), "the zigzag sent nothing");
        for (Stroke s : sent) {
          assertTrue(s.durationMs() >= P01_MS && length(s) >= P01_LENGTH - 1e-9,
              "a stroke below the wearer's limits: " + s);
        }
        // The sleeve has them all and plays every one.
        waitFor(() -> heard.played() == sent.size(), "the sleeve playing " + sent.size()
            + " strokes (events: " + heard.events + ")");
        assertTrue(heard.events.stream().noneMatch(e -> SleeveEvent.REJECTED.equals(e.type())),
            heard.events.toString());
      } finally {
        library.dispose();
      }
    }
  }

  @Test
  void aFloorReachesTheSimplifierBetweenLinesAndAMalformedOneIsIgnoredWithASentence(
      @TempDir Path state) throws Exception {
    String sleeveId = "java-floor-status";
    try (LiveSleeve live = LiveSleeve.brokerOnly(state, sleeveId)) {
      URI url = URI.create(live.mqttUrl());
      Mqtt3BlockingClient sleeve = MqttClient.builder().useMqttVersion3()
          .identifier("test-sleeve-floor-" + ProcessHandle.current().pid())
          .serverHost(url.getHost()).serverPort(url.getPort()).buildBlocking();
      sleeve.connectWith().simpleAuth().username(live.sleeveUser())
          .password(live.sleevePassword().getBytes(StandardCharsets.UTF_8)).applySimpleAuth()
          .send();
      java.util.function.Consumer<String> publishFloor = floor -> sleeve.publishWith()
          .topic("feelmysign/" + sleeveId + "/status").qos(MqttQos.AT_LEAST_ONCE).retain(true)
          .payload(("{\"online\": true, \"sleeve_id\": \"" + sleeveId + "\", \"layout\":"
              + " {\"rows\": 3, \"columns\": 4}, \"floor\": " + floor + "}")
              .getBytes(StandardCharsets.UTF_8))
          .send();
      FeelMySignTest.Sketch sketch = sketch();
      FeelMySign library = new FeelMySign(sketch).broker(live.mqttUrl())
          .login(live.senderUser(), live.senderPassword()).sleeve(sleeveId).start();
      Params own = library.params();
      try {
        drawUntil(library, library::connected, "the broker");
        // No floor known yet: the zigzag's legs go out as drawn, briefer and shorter than P01's.
        long t = zigzag(library, 0, true);
        assertTrue(library.sent().stream().anyMatch(SleeveFloorTest::belowP01),
            "the zigzag must have strokes below the wearer's limits: " + library.sent());
        assertSame(own, library.params());

        publishFloor.accept(P01_FLOOR);
        drawUntil(library, () -> library.floor() != null, "the floor with a wearer");
        assertEquals(P01_LENGTH, library.params().number("min_length"));
        t = zigzag(library, t, true);
        assertFalse(library.sent().isEmpty());
        assertTrue(library.sent().stream().noneMatch(SleeveFloorTest::belowP01),
            library.sent().toString());

        // A floor that comes while a line is drawn applies from the next line, not mid-line.
        t = zigzag(library, t, false);
        publishFloor.accept("{\"min_duration_ms\": 90, \"min_length\": 0.05}");
        SleeveFloor motors = new SleeveFloor(90, 0.05, null);
        drawUntil(library, () -> motors.equals(library.floor()), "the motors' floor");
        assertTrue(library.params().flag("strict_minimums"), "changed in the middle of a line");
        assertEquals(P01_MS, library.params().number("min_duration_ms"));
        post(library, MouseEvent.RELEASE, t, 1700, 300);
        assertTrue(library.sent().stream().noneMatch(SleeveFloorTest::belowP01),
            "the line begun under the wearer's floor ends under it: " + library.sent());
        assertTrue(sketch.statuses.contains("The sleeve plays strokes briefer than 90 ms slowed to"
            + " that, and catches up after them; a wearer file (feelmysign sleeve --wearer) sets"
            + " limits the sketch keeps to. (From the next line drawn.)"),
            sketch.statuses.toString());
        library.draw();
        Params next = library.params();
        assertEquals(90.0, next.number("floor_ms"), "applied once the line ended");
        assertFalse(next.flag("strict_minimums"));
        assertEquals(own.number("min_duration_ms"), next.number("min_duration_ms"),
            "the motors' floor alone raises no minimum");
        assertEquals(own.number("min_length"), next.number("min_length"));

        // A floor not understood: ignored, said once to the console and sleeveStatus.
        publishFloor.accept("{\"min_duration_ms\": \"fast\", \"min_length\": 0.05}");
        publishFloor.accept("{\"min_duration_ms\": \"fast\", \"min_length\": 0.05}");
        String told = "the sleeve's floor in its status is not understood and was ignored"
            + " (min_duration_ms and min_length must be numbers): the floor it said before is"
            + " kept. Its status said \"floor\": {\"min_duration_ms\": \"fast\", \"min_length\":"
            + " 0.05}";
        drawUntil(library, () -> sketch.statuses.contains(told), "the malformed floor's sentence");
        // A good status after the two bad ones: the sentence came once.
        publishFloor.accept(P01_FLOOR);
        drawUntil(library, () -> library.floor() != null && library.floor().hasWearer(),
            "the wearer's floor again");
        assertEquals(1, sketch.statuses.stream().filter(told::equals).count());
        assertEquals(new SleeveFloor(P01_MS, P01_LENGTH, "P01"), library.floor());
      } finally {
        library.dispose();
        sleeve.disconnect();
      }
    }
  }

  @Test
  void aSketchsHigherMinimumsAreKeptAndTheFloorIsTakenOnTheSketchsThread() throws Exception {
    FeelMySignTest.Sketch sketch = sketch();
    // Not started: only the network thread's side is called here, from a thread of its own.
    FeelMySign library = new FeelMySign(sketch).set("min_duration_ms", 200.0);
    Thread network = new Thread(() -> {
      library.relay().floor(new SleeveFloor(73.701, 0.05, null));
      library.relay().floor(new SleeveFloor(P01_MS, P01_LENGTH, "P01")); // the latest wins
    });
    network.start();
    network.join();
    assertNull(library.floor(), "taken before the sketch's draw()");
    library.draw();
    assertEquals(new SleeveFloor(P01_MS, P01_LENGTH, "P01"), library.floor());
    Params used = library.params();
    assertEquals(200.0, used.number("min_duration_ms"), "the sketch's higher setting is kept");
    assertEquals(P01_LENGTH, used.number("min_length"));
    assertTrue(used.flag("strict_minimums"));
    assertEquals(List.of("At least 118.4 ms and 0.62 grid units per stroke: the sleeve's floor"
        + " with wearer P01's limits; min length raised to it."), sketch.statuses);
    for (Thread thread : sketch.threads) {
      assertSame(Thread.currentThread(), thread, "a callback ran off the sketch's thread");
    }
    // The same floor again (a status republished): nothing more is said.
    library.relay().floor(new SleeveFloor(P01_MS, P01_LENGTH, "P01"));
    library.draw();
    assertEquals(1, sketch.statuses.size());
  }

  /**
   * A new user's "L" on a 900 x 600 canvas at 600 px/s under wearer T01's limits (0.5 grid units,
   * 150 ms), the pen held still for a second half-way down the stem (a drag at the same point
   * every 32 ms, as the library's still sampler gives): the stop is not played, no stroke lasting
   * across it; the piece drawn just before it, 0.3 grid units (below min_length, too far from the
   * stroke before to merge back into it), is dropped and said in the line's gaps.
   */
  @Test
  void aPieceBelowTheWearersLimitsHeldAtAStopIsNotPlayedAcrossItButSaidAsAGap() throws Exception {
    FeelMySignTest.Sketch sketch = new FeelMySignTest.Sketch();
    sketch.width = 900;
    sketch.height = 600;
    FeelMySign library = new FeelMySign(sketch).broker("mqtt://127.0.0.1:9").start();
    try {
      library.relay().floor(new SleeveFloor(150.0, 0.5, "T01"));
      library.draw();
      assertTrue(library.params().flag("strict_minimums"));
      long t = 1000;
      post(library, MouseEvent.PRESS, t, 150, 60);
      int[][] legs = {{150, 330}, {150, 540}, {750, 540}};
      int x = 150;
      int y = 60;
      for (int[] leg : legs) {
        int steps = Math.max(Math.abs(leg[0] - x), Math.abs(leg[1] - y)) / 10;
        for (int k = 1; k <= steps; k++) {
          t += k % 3 == 0 ? 16 : 17; // a frame at 60 Hz, 10 px a frame
          post(library, MouseEvent.DRAG, t, x + (leg[0] - x) * k / steps,
              y + (leg[1] - y) * k / steps);
        }
        x = leg[0];
        y = leg[1];
        if (y == 330) {
          for (int k = 0; k < 31; k++) { // held still for a second
            t += 32;
            post(library, MouseEvent.DRAG, t, x, y);
          }
        }
      }
      post(library, MouseEvent.RELEASE, t, x, y);
      library.draw();
      List<Stroke> sent = library.sent();
      assertFalse(sent.isEmpty());
      for (Stroke s : sent) {
        assertTrue(s.durationMs() < 1000, "a stroke plays the stop: " + sent);
        assertFalse(belowLimits(s, 150.0, 0.5), "a stroke below the wearer's limits: " + s);
      }
      assertTrue(sketch.statuses.stream().anyMatch(s -> s.startsWith("this line has 1 gap(s): 1"
          + " piece(s) shorter than minimumSize (0.5 grid units)")), sketch.statuses.toString());
    } finally {
      library.dispose();
    }
  }

  private static boolean belowLimits(Stroke s, double ms, double gridUnits) {
    return s.durationMs() < ms || length(s) < gridUnits - 1e-9;
  }
}
