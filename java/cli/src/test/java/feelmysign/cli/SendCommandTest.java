package feelmysign.cli;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import feelmysign.client.SleeveEvent;
import feelmysign.testing.LiveSleeve;
import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.PrintStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.io.TempDir;

/** feelmysign-java send against a real broker and sleeve simulator from the .venv. */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
class SendCommandTest {
  private LiveSleeve live;
  private Path credentials;

  private record Result(int code, String out, String err) {}

  private static Result send(String... args) {
    ByteArrayOutputStream out = new ByteArrayOutputStream();
    ByteArrayOutputStream err = new ByteArrayOutputStream();
    String[] all = new String[args.length + 1];
    all[0] = "send";
    System.arraycopy(args, 0, all, 1, args.length);
    int code = Main.run(all, new PrintStream(out, true, StandardCharsets.UTF_8),
        new PrintStream(err, true, StandardCharsets.UTF_8));
    return new Result(code, out.toString(StandardCharsets.UTF_8), err.toString(StandardCharsets.UTF_8));
  }

  @BeforeAll
  void start(@TempDir Path state) throws Exception {
    live = LiveSleeve.start(state, "send-test", List.of(), List.of());
    credentials = live.credentials();
  }

  @AfterAll
  void stop() throws InterruptedException {
    if (live != null) {
      live.close();
    }
  }

  @Test
  void aShapeAtAChosenResolutionIsPlayedByTheSleeve() throws Exception {
    try (LiveSleeve.Listening sleeve = live.listen()) {
      Result result = send("--credentials", credentials.toString(), "--shape", "square",
          "--segments", "4", "--duration-ms", "1200", "--timeout-s", "60");
      assertEquals(0, result.code(), result.err());
      assertTrue(result.out().startsWith("Sent 4 strokes to sleeve 'send-test'"), result.out());
      LiveSleeve.waitFor(() -> sleeve.played() >= 4, "the square played: " + sleeve.events);
    }
  }

  @Test
  void twoShapesInARowArePlayedWithoutAStrokeLate() throws Exception {
    try (LiveSleeve.Listening sleeve = live.listen()) {
      // Sent all at once, the second square would wait 2.4 s behind the first: late.
      for (int i = 0; i < 2; i++) {
        Result result = send("--credentials", credentials.toString(), "--shape", "square",
            "--segments", "4", "--duration-ms", "2400", "--timeout-s", "60");
        assertEquals(0, result.code(), result.err());
      }
      LiveSleeve.waitFor(
          () -> sleeve.played() + rejected(sleeve).size() >= 8, "an answer to every stroke");
      assertEquals(List.of(), rejected(sleeve));
    }
  }

  @Test
  void anIntensityNoOneFeelsIsRefusedBeforeAnythingIsSent() {
    for (String intensity : List.of("0", "0.001", "1.5")) {
      Result result = send("--credentials", credentials.toString(), "--shape", "square",
          "--intensity", intensity);
      assertEquals(2, result.code(), result.err());
      assertEquals("Error: --intensity: " + intensity + " is out of range; give a number from"
          + " 0.01 to 1 (at 0 the sleeve would play strokes no one feels). See '"
          + SendCommand.PROG + " --help'.\n", result.err().replace("\r\n", "\n"));
      assertEquals("", result.out());
    }
  }

  private static List<Map<String, Object>> rejected(LiveSleeve.Listening sleeve) {
    return sleeve.events.stream()
        .filter(e -> SleeveEvent.REJECTED.equals(e.type()))
        .map(SleeveEvent::fields)
        .toList();
  }

  @Test
  void aWrongPasswordIsSaidAndNothingSent() {
    Result result = send("--credentials", credentials.toString(), "--password", "wrong",
        "--timeout-s", "60", "0,0,2,0,500");
    assertEquals(1, result.code());
    assertTrue(result.err().startsWith("Error: the broker refused the login of"), result.err());
  }

  @Test
  void credentialsAndBrokerProblemsAreSaidAsTheReferenceSaysThem(@TempDir Path dir)
      throws IOException {
    Path missing = dir.resolve("nowhere.json");
    Result absent = send("--credentials", missing.toString(), "0,0,2,0,500");
    assertEquals(1, absent.code());
    assertEquals("Error: No credentials file at " + missing + "; start the broker first"
        + " ('feelmysign broker') or pass the file it wrote (STATE_DIR/credentials.json, or"
        + " STATE_DIR/sleeve-credentials.json for a sleeve).\n", absent.err());
    Path other = dir.resolve("other.json");
    Files.writeString(other, "{\"canvas\": {\"width_px\": 10}}");
    Result notCredentials = send("--credentials", other.toString(), "0,0,2,0,500");
    assertEquals(1, notCredentials.code());
    assertTrue(notCredentials.err().startsWith("Error: The credentials file " + other
        + " is not usable: it lacks mqtt_url, ws_url, sleeve{id, username, password} or"
        + " sender{...}. Fix it,"), notCredentials.err());
    Path text = dir.resolve("notes.txt");
    Files.writeString(text, "not json");
    Result notJson = send("--credentials", text.toString(), "0,0,2,0,500");
    assertEquals(1, notJson.code());
    assertTrue(notJson.err().startsWith("Error: The credentials file " + text
        + " is not usable: it cannot be read as JSON"), notJson.err());
    // Nothing listening: said at once, not after --timeout-s.
    int port;
    try (java.net.ServerSocket socket = new java.net.ServerSocket(0)) {
      port = socket.getLocalPort();
    }
    Result nobody = send("--broker", "mqtt://127.0.0.1:" + port, "--timeout-s", "600", "0,0,2,0,500");
    assertEquals(1, nobody.code());
    assertEquals("Error: Nothing accepts connections at mqtt://127.0.0.1:" + port
        + " (connection refused): start one with 'feelmysign broker' or 'make up', or give the"
        + " right --broker URL.\n", nobody.err());
  }

  @Test
  void aLoginRefusedWithoutAUserNameSaysSoAndWhereThePasswordIs() {
    Result result = send("--broker", live.mqttUrl(), "--timeout-s", "60", "0,0,2,0,500");
    assertEquals(1, result.code());
    assertTrue(result.err().contains("without a user name") && result.err().contains("credentials.json")
        && !result.err().contains("null"), result.err());
  }

  @Test
  void badInputIsRefusedBeforeAnythingIsSent() {
    Result outside = send("--broker", "mqtt://127.0.0.1:1", "0,0,9,0,500");
    assertEquals(1, outside.code());
    assertTrue(outside.err().contains("outside the 3-row x 4-column grid")
        && outside.err().contains("Nothing was sent."), outside.err());
    Result segments = send("--shape", "square", "--segments", "6");
    assertEquals(1, segments.code());
    assertEquals("Error: segments of a square = 6 is not allowed; it must be a multiple of 4"
        + " from 4 to 64 (each of its 4 sides split into equal strokes)\n", segments.err());
    Result both = send("--shape", "circle", "0,0,1,0,500");
    assertEquals(2, both.code());
  }
}
