package feelmysign.cli;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import com.fasterxml.jackson.databind.JsonNode;
import com.fasterxml.jackson.databind.ObjectMapper;
import feelmysign.testing.LiveSleeve;
import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.PrintStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * {@code feelmysign-java simplify} against the reference {@code feelmysign simplify}, run from
 * the repository's .venv: LASA demonstrations, the gesture logs of research/gestures, seeded
 * random drawings with seeded flags of both algorithms, broken recordings and wrong command
 * lines, and --help (src/test/python/simplify_cases.py writes them with what the reference
 * printed; its help under this port's name, as argparse wraps the usage after it). The JSON and
 * the help must be the same to the byte, the exit code the same, and an error the same sentence.
 */
class SimplifyAgainstReferenceTest {
  @TempDir Path work;

  @Test
  void printsWhatTheReferencePrints() throws IOException, InterruptedException {
    Path repo = LiveSleeve.repository();
    Path python = repo.resolve(".venv/bin/python");
    if (!Files.isExecutable(python)) {
      fail(python + " is missing: run 'make .venv/.installed-stamp' (make java-test does)");
    }
    Path script = repo.resolve("java/cli/src/test/python/simplify_cases.py");
    Process process =
        new ProcessBuilder(python.toString(), script.toString(), work.toString())
            .redirectErrorStream(true)
            .start();
    String log = new String(process.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
    assertTrue(process.waitFor(10, TimeUnit.MINUTES), "the reference did not finish");
    assertEquals(0, process.exitValue(), "the reference's cases failed:\n" + log);

    JsonNode cases = new ObjectMapper().readTree(work.resolve("cases.json").toFile());
    assertTrue(cases.size() > 300, "too few cases: " + cases.size());
    List<String> differences = new ArrayList<>();
    int json = 0;
    for (JsonNode c : cases) {
      List<String> args = new ArrayList<>(List.of("simplify"));
      c.get("args").forEach(a -> args.add(a.asText()));
      ByteArrayOutputStream out = new ByteArrayOutputStream();
      ByteArrayOutputStream err = new ByteArrayOutputStream();
      int code;
      try (PrintStream o = new PrintStream(out, true, StandardCharsets.UTF_8);
          PrintStream e = new PrintStream(err, true, StandardCharsets.UTF_8)) {
        code = Main.run(args.toArray(String[]::new), o, e);
      }
      String stdout = out.toString(StandardCharsets.UTF_8);
      String stderr = err.toString(StandardCharsets.UTF_8);
      String where = c.get("name").asText() + " " + c.get("args");
      int expectedCode = c.get("code").asInt();
      if (code != expectedCode) {
        differences.add(where + ": exit " + code + ", the reference " + expectedCode + "\n  " + stderr);
        continue;
      }
      if (!stdout.equals(c.get("stdout").asText())) {
        differences.add(where + ": stdout differs\n  java: " + cut(stdout) + "\n  ref:  "
            + cut(c.get("stdout").asText()));
      }
      // An error: the same sentence. A usage error ends with the command to ask for help, which
      // is this port's own (the reference names its top-level command for an unknown option).
      String expectedErr = withoutHelpCommand(c.get("stderr").asText());
      if (!withoutHelpCommand(stderr).equals(expectedErr)) {
        differences.add(where + ": stderr differs\n  java: " + stderr + "  ref:  " + expectedErr);
      }
      if (expectedCode == 0 && stdout.startsWith("{")) {
        json++;
      }
    }
    assertTrue(json > 250, "too few cases printed strokes: " + json);
    assertTrue(differences.isEmpty(),
        differences.size() + " of " + cases.size() + " cases differ:\n"
            + String.join("\n", differences.subList(0, Math.min(20, differences.size()))));
  }

  private static String withoutHelpCommand(String stderr) {
    return stderr.replaceAll("See '[^']*--help'\\.", "See 'PROG --help'.");
  }

  private static String cut(String text) {
    return text.length() <= 400 ? text : text.substring(0, 400) + "...";
  }
}
