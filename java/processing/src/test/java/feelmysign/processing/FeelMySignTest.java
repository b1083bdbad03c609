package feelmysign.processing;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertSame;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import feelmysign.client.SleeveClient;
import feelmysign.client.SleeveEvent;
import feelmysign.client.WearerState;
import java.io.IOException;
import java.net.ServerSocket;
import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import processing.core.PApplet;
import processing.core.PConstants;
import processing.event.MouseEvent;

/**
 * The library without a screen: its hooks are called as Processing calls them (a sketch that
 * is not run), against a broker that is not there.
 */
class FeelMySignTest {
  /** A sketch with the library's two optional callbacks, recording where they ran. */
  public static class Sketch extends PApplet {
    final List<String> statuses = new ArrayList<>();
    final List<SleeveEvent> events = new ArrayList<>();
    final List<WearerState> wearers = new ArrayList<>();
    final List<Thread> threads = new ArrayList<>();

    public void sleeveStatus(String sentence) {
      statuses.add(sentence);
      threads.add(Thread.currentThread());
    }

    public void sleeveEvent(SleeveEvent event) {
      events.add(event);
      threads.add(Thread.currentThread());
    }

    public void sleeveWearer(WearerState wearer) {
      wearers.add(wearer);
      threads.add(Thread.currentThread());
    }
  }

  private static int unusedPort() throws IOException {
    try (ServerSocket socket = new ServerSocket(0)) {
      return socket.getLocalPort();
    }
  }

  private static void post(FeelMySign library, int action, long millis, int x, int y) {
    library.mouseEvent(new MouseEvent(null, millis, action, 0, x, y, PConstants.LEFT, 1));
  }

  @Test
  void theWearersChoiceReachesTheSketchTypedAndSaidOnItsOwnThread() throws Exception {
    Sketch sketch = new Sketch();
    FeelMySign library = new FeelMySign(sketch);
    assertEquals(WearerState.NONE, library.wearer());
    WearerState paused = new WearerState(true, "button", 0.6, null);
    Thread network =
        new Thread(
            () -> {
              library.relay().wearer(paused);
              library.relay().wearer(paused); // republished for another reason: said once
              library.relay().wearer(WearerState.NONE);
            });
    network.start();
    network.join();
    assertTrue(sketch.wearers.isEmpty(), "nothing before the sketch's draw()");
    library.draw();
    assertEquals(List.of(paused, WearerState.NONE), sketch.wearers);
    assertEquals(
        List.of(
            "the wearer paused the sleeve: strokes are refused until the wearer resumes it; wait"
                + " for the wearer (and a ceiling of 60 %)",
            "the wearer resumed the sleeve: strokes play again"),
        sketch.statuses);
    assertEquals(WearerState.NONE, library.wearer());
    for (Thread thread : sketch.threads) {
      assertSame(Thread.currentThread(), thread, "a callback ran off the sketch's thread");
    }
  }

  @Test
  void aFloatLiteralIsTheNumberWritten() {
    // In a .pde, 0.1 is a float; set() takes it as written, not as the float's exact value.
    FeelMySign library = new FeelMySign(new Sketch()).set("max_error", 0.1f).set("rest_ms", 150f);
    assertEquals(0.1, library.params().get("max_error"));
    assertEquals(150.0, library.params().get("rest_ms"));
    assertTrue(library.params().values().toString().contains("max_error=0.1,"),
        library.params().values().toString());
    FeelMySign paper = new FeelMySign(new Sketch()).angle().set("minimumSize", 0.3f);
    assertEquals(0.3, paper.params().get("min_length"));
  }

  @Test
  void theSketchIsToldWhenTheSleeveGoesOfflineAndComesBack() throws Exception {
    Sketch sketch = new Sketch();
    FeelMySign library = new FeelMySign(sketch);
    String online = "{\"online\": true, \"sleeve_id\": \"sleeve1\"}";
    String offline = "{\"online\": false, \"sleeve_id\": \"sleeve1\"}";
    Thread network =
        new Thread(
            () -> {
              library.relay().status(online); // as it was when the sketch started: not said
              library.relay().status(online); // republished for another reason: not said
              library.relay().status(offline); // the broker's last will
              library.relay().status(offline);
              library.relay().status("{not json"); // not understood: nothing said, nothing kept
              library.relay().status(online);
              library.relay().status(""); // cleared: the client says it (noSleeve), not this
              library.relay().noSleeve(SleeveClient.noSleeveSentence("sleeve1"));
              library.relay().status(online); // a sleeve starts on the id
            });
    network.start();
    network.join();
    library.draw();
    assertEquals(
        List.of(
            "sleeve sleeve1 is offline: no new stroke is felt. Strokes sent now wait at the broker"
                + " and play if it is back within its age limit (10 s unless set; older ones are"
                + " refused as stale); if it crashed, a motor it was driving may run until it"
                + " restarts",
            "sleeve sleeve1 is online again",
            "no sleeve listens on id 'sleeve1': nothing has ever reported there, so strokes sent"
                + " now are not felt; check the sleeve id (a sleeve prints its id when it starts)",
            "sleeve sleeve1 is online: strokes sent from now on are felt"),
        sketch.statuses);
    for (Thread thread : sketch.threads) {
      assertSame(Thread.currentThread(), thread, "a callback ran off the sketch's thread");
    }
  }

  @Test
  void aBrokerOutOfReachIsSaidOnceAndStrokesWaitInTheOutbox() throws Exception {
    Sketch sketch = new Sketch();
    sketch.width = 1920;
    sketch.height = 1080;
    String url = "mqtt://127.0.0.1:" + unusedPort();
    FeelMySign library = new FeelMySign(sketch).broker(url).angle().start();
    // The reference's sentence, not the network library's exception.
    String told =
        "Nothing accepts connections at " + url + " (connection refused): start one with"
            + " 'feelmysign broker' or 'make up', or give the right broker URL. Retrying every"
            + " 2 s.";
    try {
      // Nothing reaches the sketch until its draw(): the hook, called here as Processing does.
      long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(60);
      while (!sketch.statuses.contains(told)) {
        if (System.nanoTime() > deadline) {
          fail("the broker's absence was not said: " + sketch.statuses);
        }
        library.draw();
        Thread.sleep(20);
      }
      // A square drawn meanwhile: its strokes are kept for when the broker is back.
      long t = 0;
      post(library, MouseEvent.PRESS, t, 200, 200);
      int[][] corners = {{1400, 200}, {1400, 900}, {200, 900}, {200, 200}};
      int x = 200;
      int y = 200;
      for (int[] c : corners) {
        for (int k = 1; k <= 40; k++) {
          t += 16;
          post(library, MouseEvent.DRAG, t, x + (c[0] - x) * k / 40, y + (c[1] - y) * k / 40);
        }
        x = c[0];
        y = c[1];
      }
      post(library, MouseEvent.RELEASE, t, x, y);
      for (int i = 0; i < 10; i++) {
        library.draw();
      }
      assertFalse(library.connected());
      assertTrue(library.sent().size() >= 4, "a square is four strokes or more");
      assertEquals(library.sent().size(), library.unsent(), "every stroke waits in the outbox");
      // A tap: too short to feel (the paper's NotEnoughDistance), said with what to tune.
      int before = library.sent().size();
      post(library, MouseEvent.PRESS, t + 500, 700, 500);
      post(library, MouseEvent.RELEASE, t + 600, 700, 500);
      library.draw();
      assertTrue(sketch.statuses.stream().anyMatch(
          s -> s.contains("gap") && s.contains("shorter than minimumSize")), sketch.statuses.toString());
      assertEquals(0, library.sent().size(), "the tap cleared the drawing (clickClear) and sent nothing");
      assertTrue(before > 0);
      // A stroke of the sketch's own outside the grid (the paper's A.3.1): said, not sent.
      assertEquals(null, library.send(new feelmysign.protocol.Stroke(0, 0, 9, 0, 500)));
      library.draw();
      assertTrue(sketch.statuses.stream().anyMatch(s -> s.startsWith("a stroke was not sent: end (9, 0)"
          + " is outside the 3-row x 4-column grid")), sketch.statuses.toString());
      assertEquals(new HashSet<>(sketch.statuses).size(), sketch.statuses.size(),
          "a sentence said twice: " + sketch.statuses);
      for (Thread thread : sketch.threads) {
        assertSame(Thread.currentThread(), thread, "a callback ran off the sketch's thread");
      }
    } finally {
      library.dispose();
    }
  }

  @Test
  void eventsFromTheNetworkThreadReachTheSketchOnlyInsideDraw() throws Exception {
    Sketch sketch = new Sketch();
    // Not started: no connection, so only these events are queued.
    FeelMySign library = new FeelMySign(sketch);
    try {
      Thread network = new Thread(() -> {
        for (int i = 0; i < FeelMySign.EVENT_QUEUE + 50; i++) {
          library.relay().event(SleeveEvent.parse(
              "{\"type\": \"played\", \"drawing\": \"d\", \"seq\": " + i + "}"));
        }
      });
      network.start();
      network.join();
      assertTrue(sketch.events.isEmpty(), "an event was delivered outside draw()");
      library.draw();
      // Bounded: what came faster than the sketch drew is counted, not kept.
      assertEquals(FeelMySign.EVENT_QUEUE, sketch.events.size());
      assertEquals(FeelMySign.EVENT_HISTORY, library.events().size());
      assertEquals(0L, sketch.events.get(0).seq());
      for (Thread thread : sketch.threads) {
        assertSame(Thread.currentThread(), thread);
      }
    } finally {
      library.dispose();
    }
  }

  /** A sketch that records the lines it is asked to draw instead of drawing them. */
  public static class LineSketch extends PApplet {
    final List<float[]> lines = new ArrayList<>();

    @Override
    public void line(float x1, float y1, float x2, float y2) {
      lines.add(new float[] {x1, y1, x2, y2});
    }
  }

  @Test
  void drawPlayedDrawsTheSentStrokesWhosePlayedEventArrived() throws Exception {
    LineSketch sketch = new LineSketch();
    sketch.width = 400;
    sketch.height = 300;
    FeelMySign library = new FeelMySign(sketch)
        .broker("mqtt://127.0.0.1:" + unusedPort()).set("stretch", true).start();
    try {
      var first = library.send(new feelmysign.protocol.Stroke(0, 0, 3, 0, 500));
      var second = library.send(new feelmysign.protocol.Stroke(3, 0, 3, 2, 500));
      var third = library.send(new feelmysign.protocol.Stroke(3, 2, 0, 2, 500));
      assertTrue(first.drawing() != null && first.seq() != null, "sent without drawing or seq");
      // The sleeve's events carry no geometry: only the drawing and seq of what it played.
      library.relay().event(SleeveEvent.parse("{\"type\": \"played\", \"drawing\": \""
          + first.drawing() + "\", \"seq\": " + first.seq() + "}"));
      library.relay().event(SleeveEvent.parse("{\"type\": \"adjusted\", \"drawing\": \""
          + third.drawing() + "\", \"seq\": " + third.seq() + ", \"reason\": \"too_fast\"}"));
      library.relay().event(SleeveEvent.parse("{\"type\": \"rejected\", \"drawing\": \""
          + second.drawing() + "\", \"seq\": " + second.seq() + ", \"reason\": \"late\"}"));
      library.relay().event(SleeveEvent.parse(
          "{\"type\": \"played\", \"drawing\": \"another\", \"seq\": " + second.seq() + "}"));
      library.draw();
      sketch.lines.clear();
      library.drawPlayed();
      List<List<Float>> drawn = new ArrayList<>();
      for (float[] l : sketch.lines) {
        drawn.add(List.of(l[0], l[1], l[2], l[3]));
      }
      // Stretched: column 3 of 4 is x 400, row 2 of 3 is y 300.
      assertEquals(List.of(List.of(0f, 0f, 400f, 0f), List.of(400f, 300f, 0f, 300f)), drawn);
    } finally {
      library.dispose();
    }
  }

  @Test
  void aSketchThatNeverClearsKeepsOnlyTheLatestStrokesAndLine() throws Exception {
    LineSketch sketch = new LineSketch();
    sketch.width = 400;
    sketch.height = 300;
    // Nothing cleared on press: a session of hours would otherwise keep every stroke it sent.
    FeelMySign library = new FeelMySign(sketch).broker("mqtt://127.0.0.1:" + unusedPort())
        .set("clear_on_press", false).set("stretch", true).start();
    try {
      int count = FeelMySign.HISTORY_STROKES * 3;
      feelmysign.protocol.Stroke last = null;
      for (int i = 0; i < count; i++) {
        last = library.send(new feelmysign.protocol.Stroke(0, i % 3, 3, 2 - i % 3, 100));
      }
      List<feelmysign.protocol.Stroke> kept = library.sent();
      assertEquals(FeelMySign.HISTORY_STROKES, kept.size());
      assertEquals(last, kept.get(kept.size() - 1), "the newest stroke is kept");
      assertEquals((long) count - FeelMySign.HISTORY_STROKES, kept.get(0).seq(),
          "the oldest go first");
      sketch.lines.clear();
      library.drawSent();
      assertEquals(FeelMySign.HISTORY_STROKES, sketch.lines.size(), "drawSent draws what is kept");

      // One drag of minutes: the on-screen line keeps its start and the latest samples.
      post(library, MouseEvent.PRESS, 0, 10, 10);
      for (int i = 1; i <= FeelMySign.LINE_SAMPLES + 500; i++) {
        post(library, MouseEvent.DRAG, 16L * i, 10 + i % 300, 10 + i % 200);
      }
      sketch.lines.clear();
      library.drawLine();
      assertEquals(FeelMySign.LINE_SAMPLES - 1, sketch.lines.size());
      assertEquals(10f, sketch.lines.get(0)[0], "the line starts where the press was");
    } finally {
      library.dispose();
    }
  }

  @Test
  void thePaperSketchSaysTheAngleSimplifiersDefaults() throws IOException {
    String sketch = java.nio.file.Files.readString(
        java.nio.file.Path.of("examples/PaperSketch/PaperSketch.pde"));
    feelmysign.simplify.Params defaults = feelmysign.simplify.Params.angle();
    String[][] named = {
      {"frameMax", "frame_max"}, {"checkFrame", "check_frames"}, {"maxAngleDifDeg", "max_angle_deg"}
    };
    for (String[] name : named) {
      java.util.regex.Matcher said =
          java.util.regex.Pattern.compile("\\b" + name[0] + " (\\d+(?:\\.\\d+)?)").matcher(sketch);
      assertTrue(said.find(), name[0] + " is not in the sketch's comment");
      assertEquals(defaults.number(name[1]), Double.parseDouble(said.group(1)), name[0]);
    }
  }

  @Test
  void aParameterOutOfRangeSaysWhichAndTheRange() {
    FeelMySign library = new FeelMySign(new Sketch()).angle();
    IllegalArgumentException error =
        assertThrows(IllegalArgumentException.class, () -> library.set("checkFrame", 1));
    assertTrue(error.getMessage().contains("1 is not allowed; it must be in [2, 600]"),
        error.getMessage());
  }

  @Test
  void livingFramesAreTheFramesOfARecording() {
    // The same samples, all at once (Frames.fromSamples) and one by one (LiveFrames).
    java.util.Random random = new java.util.Random(7);
    for (int trial = 0; trial < 200; trial++) {
      List<feelmysign.simplify.Sample> samples = new ArrayList<>();
      double t = random.nextInt(1000);
      int n = 1 + random.nextInt(40);
      for (int i = 0; i < n; i++) {
        samples.add(new feelmysign.simplify.Sample(t, random.nextInt(500), random.nextInt(500)));
        t += random.nextInt(4) == 0 ? 0 : random.nextInt(60);
      }
      double fps = new double[] {60, 30, 24, 7.5}[random.nextInt(4)];
      LiveFrames live = new LiveFrames(fps);
      List<feelmysign.simplify.Sample> got = new ArrayList<>(live.press(samples.get(0)));
      for (int i = 1; i < n; i++) {
        got.addAll(live.move(samples.get(i)));
      }
      got.addAll(live.release());
      assertEquals(feelmysign.simplify.Frames.fromSamples(samples, fps), got,
          "trial " + trial + " at " + fps + " fps: " + samples);
    }
  }

  @Test
  void aStillPensSamplesLeaveTheFramesOfThePathAsTheyWere() {
    // The samples a still pen is given (its last position, later) go through the frames too:
    // each frame holds where the pen is either way, so the frames are those of the path without
    // them, taken as the rest lasts instead of at the next event.
    java.util.Random random = new java.util.Random(11);
    for (int trial = 0; trial < 200; trial++) {
      List<feelmysign.simplify.Sample> drawn = new ArrayList<>();
      List<feelmysign.simplify.Sample> withStill = new ArrayList<>();
      double t = random.nextInt(1000);
      int n = 2 + random.nextInt(30);
      for (int i = 0; i < n; i++) {
        feelmysign.simplify.Sample sample =
            new feelmysign.simplify.Sample(t, random.nextInt(500), random.nextInt(500));
        drawn.add(sample);
        withStill.add(sample);
        double gap = random.nextInt(3) == 0 ? 100 + random.nextInt(400) : random.nextInt(20);
        if (i < n - 1) {
          // A rest: a still sample every STILL_SAMPLE_MS while no event comes.
          for (double s = t + FeelMySign.STILL_SAMPLE_MS; s < t + gap;
              s += FeelMySign.STILL_SAMPLE_MS) {
            withStill.add(new feelmysign.simplify.Sample(s, sample.x(), sample.y()));
          }
        }
        t += gap;
      }
      double fps = new double[] {60, 30, 24, 7.5}[random.nextInt(4)];
      LiveFrames live = new LiveFrames(fps);
      List<feelmysign.simplify.Sample> got = new ArrayList<>(live.press(withStill.get(0)));
      for (int i = 1; i < withStill.size(); i++) {
        got.addAll(live.move(withStill.get(i)));
      }
      got.addAll(live.release());
      assertEquals(feelmysign.simplify.Frames.fromSamples(drawn, fps), got,
          "trial " + trial + " at " + fps + " fps: " + withStill);
    }
  }
}
