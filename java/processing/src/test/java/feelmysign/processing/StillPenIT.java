package feelmysign.processing;

import static feelmysign.testing.LiveSleeve.waitFor;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import feelmysign.client.SleeveEvent;
import feelmysign.protocol.Stroke;
import feelmysign.simplify.CanvasMapping;
import feelmysign.testing.LiveSleeve;
import java.awt.Component;
import java.awt.Point;
import java.awt.Robot;
import java.awt.event.InputEvent;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;
import processing.core.PApplet;

/**
 * A pen held still in a running sketch, on Xvfb's screen, with the X server's own mouse
 * ({@link Robot}): the events are AWT's, stamped by its clock, and the library's draw() hook runs
 * on the sketch's thread every frame. The stroke drawn up to the stop is sent while the mouse
 * button is down and the mouse still, and a real {@code feelmysign sleeve --backend sim} (on a
 * real Mosquitto) plays it before the mouse moves again. make java-test runs it under xvfb-run.
 */
class StillPenIT {
  private static final long MOVE_MS = 16;
  private static final long REST_MS = 1000;
  /** As {@link StillPenTest}'s bound, and as far below the rest. */
  private static final long SENT_WITHIN_MS = 400;

  /** A sketch that draws as ModernSketch does, the library at its defaults (the window simplifier). */
  public static class StillSketch extends PApplet {
    static volatile String broker;
    static volatile String user;
    static volatile String password;
    static volatile String sleeveId;
    volatile FeelMySign sleeve;

    @Override
    public void settings() {
      size(640, 480); // xvfb-run's default screen is 640 x 480
    }

    @Override
    public void setup() {
      sleeve = new FeelMySign(this).broker(broker).login(user, password).sleeve(sleeveId).start();
    }

    @Override
    public void draw() {
      background(250);
      stroke(200);
      sleeve.drawSent();
      stroke(0);
      sleeve.drawLine();
    }
  }

  private static long elapsedMs(long sinceNanos) {
    return TimeUnit.NANOSECONDS.toMillis(System.nanoTime() - sinceNanos);
  }

  private static boolean endsAt(Stroke s, double gridX, double gridY) {
    return Math.abs(s.endX() - gridX) < 1e-6 && Math.abs(s.endY() - gridY) < 1e-6;
  }

  /** The mouse moved in a straight line from {@code from} to {@code to}, a move every 16 ms. */
  private static void moveMouse(Robot robot, Point from, Point to, long ms)
      throws InterruptedException {
    long start = System.nanoTime();
    long steps = ms / MOVE_MS;
    for (long k = 1; k <= steps; k++) {
      long due = k * MOVE_MS - elapsedMs(start);
      if (due > 0) {
        Thread.sleep(due);
      }
      robot.mouseMove((int) (from.x + (to.x - from.x) * k / steps),
          (int) (from.y + (to.y - from.y) * k / steps));
    }
  }

  @Test
  void theRealMouseHeldStillInARunningSketchSendsTheStrokeDrawnUpToIt(@TempDir Path state)
      throws Exception {
    if (System.getenv("DISPLAY") == null) {
      fail("no X display: run 'make java-test', which starts Xvfb (xvfb-run) for this test");
    }
    try (LiveSleeve live = LiveSleeve.start(state, "java-still-pen-it", List.of(), List.of());
        LiveSleeve.Listening heard = live.listen()) {
      StillSketch.broker = live.mqttUrl();
      StillSketch.user = live.senderUser();
      StillSketch.password = live.senderPassword();
      StillSketch.sleeveId = live.sleeveId();
      StillSketch sketch = new StillSketch();
      PApplet.runSketch(new String[] {"--location=0,0", "StillSketch"}, sketch);
      try {
        waitFor(() -> sketch.frameCount > 3 && sketch.sleeve != null, "the sketch's frames");
        FeelMySign library = sketch.sleeve;
        waitFor(library::connected, "the sketch's connection to the broker");
        Component canvas = (Component) sketch.getSurface().getNative();
        Point origin = canvas.getLocationOnScreen();
        CanvasMapping mapping = library.params().mapping();
        Point a = new Point(origin.x + 60, origin.y + 80);
        Point b = new Point(origin.x + 380, origin.y + 330);
        Point c = new Point(origin.x + 600, origin.y + 80);
        double stopX = mapping.gridX(b.x - origin.x);
        double stopY = mapping.gridY(b.y - origin.y);

        Robot robot = new Robot();
        robot.mouseMove(a.x, a.y);
        Thread.sleep(100);
        robot.mousePress(InputEvent.BUTTON1_DOWN_MASK);
        moveMouse(robot, a, b, 480);
        long stopped = System.nanoTime();
        // Held still, the button down: the X server sends nothing.
        long sentAfter = -1;
        long playedAfter = -1;
        Stroke upToStop = null;
        while (elapsedMs(stopped) < REST_MS) {
          Thread.sleep(5);
          if (upToStop == null) {
            upToStop = library.sent().stream().filter(s -> endsAt(s, stopX, stopY)).findFirst()
                .orElse(null);
            sentAfter = upToStop == null ? -1 : elapsedMs(stopped);
          }
          Stroke sent = upToStop;
          if (sent != null && playedAfter < 0 && heard.events.stream().anyMatch(
              e -> sent.drawing().equals(e.drawing()) && sent.seq().equals(e.seq())
                  && SleeveEvent.PLAYED.equals(e.type()))) {
            playedAfter = elapsedMs(stopped);
          }
        }
        long restMs = elapsedMs(stopped);
        moveMouse(robot, b, c, 320);
        robot.mouseRelease(InputEvent.BUTTON1_DOWN_MASK);
        double endX = mapping.gridX(c.x - origin.x);
        double endY = mapping.gridY(c.y - origin.y);
        waitFor(() -> library.sent().stream().anyMatch(s -> endsAt(s, endX, endY)),
            "the path after the rest, to where the mouse was released");

        System.out.println("still mouse: the stroke up to it sent " + sentAfter + " ms and played "
            + playedAfter + " ms after the mouse stopped; rest " + restMs + " ms");
        assertTrue(upToStop != null, "the stroke drawn up to the still mouse was not sent in "
            + restMs + " ms: " + library.sent());
        assertTrue(sentAfter <= SENT_WITHIN_MS,
            "sent " + sentAfter + " ms after the mouse stopped (bound " + SENT_WITHIN_MS + " ms)");
        assertTrue(playedAfter >= 0, "the sleeve did not play it while the mouse rested "
            + restMs + " ms: " + heard.events);
        for (Stroke s : library.sent()) {
          assertTrue(s.durationMs() < restMs - 100,
              "a stroke spans the rest of " + restMs + " ms: " + s);
        }
      } finally {
        sketch.noLoop();
        sketch.getSurface().setVisible(false);
        sketch.dispose(); // the library's dispose hook closes its client
      }
    }
  }
}
