package feelmysign.processing;

import static feelmysign.testing.LiveSleeve.waitFor;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import feelmysign.client.SleeveClient;
import feelmysign.protocol.Stroke;
import feelmysign.testing.LiveSleeve;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;

/**
 * A sketch sending to an id no sleeve listens on is told so, on the console and to
 * sleeveStatus, within a few seconds of connecting, and once more when it sends strokes there;
 * not per stroke. Against a real Mosquitto and sleeve simulator ({@code feelmysign broker},
 * {@code feelmysign sleeve --backend sim}) on another id: a retained status exists, but not on
 * the sketch's id. The sketch is not run: its draw() hook is called as Processing calls it.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class WrongSleeveIdTest {
  private static final String RUNNING = "java-sleeve1";
  private static final String WRONG = "arm1";

  private LiveSleeve live;

  @BeforeAll
  void startBrokerAndSleeve(@TempDir Path state) throws Exception {
    live = LiveSleeve.start(state, RUNNING, List.of(), List.of());
    try (LiveSleeve.Listening sleeveUp = live.listen()) {
      // The sleeve has said its status: the broker holds it, on the sleeve's own id.
      assertFalse(sleeveUp.statuses.isEmpty());
    }
  }

  @AfterAll
  void stopThem() throws InterruptedException {
    if (live != null) {
      live.close();
    }
  }

  private FeelMySign library(FeelMySignTest.Sketch sketch, String sleeveId) {
    sketch.width = 900;
    sketch.height = 600;
    return new FeelMySign(sketch).broker(live.mqttUrl())
        .login(live.senderUser(), live.senderPassword()).sleeve(sleeveId).start();
  }

  private static long connect(FeelMySign library) throws InterruptedException {
    waitFor(() -> {
      library.draw();
      return library.connected();
    }, "the broker");
    return System.nanoTime();
  }

  /** Frames of the sketch for {@code ms}: the network's news handed to it. */
  private static void drawFor(FeelMySign library, long ms) throws InterruptedException {
    long end = System.nanoTime() + TimeUnit.MILLISECONDS.toNanos(ms);
    while (System.nanoTime() < end) {
      library.draw();
      Thread.sleep(16);
    }
  }

  private static long told(FeelMySignTest.Sketch sketch, String sentence) {
    return sketch.statuses.stream().filter(sentence::equals).count();
  }

  private static List<Stroke> zigzag() {
    List<Stroke> strokes = new ArrayList<>();
    for (int k = 0; k < 8; k++) {
      strokes.add(new Stroke(k % 2 == 0 ? 0 : 3, 0, k % 2 == 0 ? 3 : 0, 2, 100));
    }
    return strokes;
  }

  @Test
  void aWrongSleeveIdIsSaidSoonAfterConnectingAndOnceMoreWhenStrokesAreSent() throws Exception {
    FeelMySignTest.Sketch sketch = new FeelMySignTest.Sketch();
    FeelMySign library = library(sketch, WRONG);
    String sentence = SleeveClient.noSleeveSentence(WRONG);
    assertEquals(
        "no sleeve listens on id 'arm1': nothing has ever reported there, so strokes sent now"
            + " are not felt; check the sleeve id (a sleeve prints its id when it starts)",
        sentence);
    try {
      long connected = connect(library);
      waitFor(() -> {
        library.draw();
        return told(sketch, sentence) == 1;
      }, "the sentence for the wrong sleeve id");
      long afterMs = TimeUnit.NANOSECONDS.toMillis(System.nanoTime() - connected);
      // The retained status is awaited for STATUS_WAIT_MS (2.5 s); a busy machine adds to it.
      assertTrue(afterMs >= SleeveClient.STATUS_WAIT_MS - 100 && afterMs < 10_000,
          "said " + afterMs + " ms after connecting");

      // Strokes sent there: said once more, not per stroke.
      library.sendDrawing(zigzag());
      library.sendDrawing(zigzag());
      waitFor(() -> {
        library.draw();
        return library.unsent() == 0;
      }, "the broker taking all 16 strokes");
      drawFor(library, 500);
      assertEquals(8, library.sent().size()); // the second drawing's (clear_on_press)
      assertEquals(2, told(sketch, sentence), sketch.statuses.toString());
      assertTrue(library.events().isEmpty(), "an event from nowhere: " + library.events());
    } finally {
      library.dispose();
    }
  }

  @Test
  void theRightSleeveIdIsNotWarnedAbout() throws Exception {
    FeelMySignTest.Sketch sketch = new FeelMySignTest.Sketch();
    FeelMySign library = library(sketch, RUNNING);
    try {
      connect(library);
      library.sendDrawing(zigzag());
      waitFor(() -> {
        library.draw();
        return library.events().stream().filter(e -> Long.valueOf(7).equals(e.seq())).anyMatch(
            e -> e.type().equals("played") || e.type().equals("adjusted"));
      }, "the last stroke played");
      drawFor(library, SleeveClient.STATUS_WAIT_MS + 1000);
      library.sendDrawing(zigzag());
      drawFor(library, 300);
      assertTrue(sketch.statuses.stream().noneMatch(s -> s.contains("no sleeve listens")),
          sketch.statuses.toString());
    } finally {
      library.dispose();
    }
  }
}
