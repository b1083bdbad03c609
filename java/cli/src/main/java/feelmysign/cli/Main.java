package feelmysign.cli;

import java.io.PrintStream;
import java.nio.charset.StandardCharsets;

/**
 * {@code feelmysign-java}: the command line of the Java port. Exit codes as the reference's:
 * 0 done, 1 an error in what was given (one "Error: ..." line), 2 a usage error, 70 a bug.
 */
public final class Main {
  private Main() {}

  static final String PROG = "feelmysign-java";

  public static void main(String[] args) {
    PrintStream out = new PrintStream(System.out, false, StandardCharsets.UTF_8);
    PrintStream err = new PrintStream(System.err, true, StandardCharsets.UTF_8);
    int code = run(args, out, err);
    out.flush();
    System.exit(code);
  }

  /** Run one command, printing to {@code out} and {@code err}; the exit code. */
  public static int run(String[] args, PrintStream out, PrintStream err) {
    if (args.length == 0 || args[0].equals("-h") || args[0].equals("--help")) {
      PrintStream to = args.length == 0 ? err : out;
      to.println("usage: " + PROG + " {simplify,send} ...");
      to.println();
      to.println("  simplify  cut a recorded drawing into the strokes a sender would send");
      to.println("  send      send strokes, a shape or a recording to a sleeve");
      return args.length == 0 ? 2 : 0;
    }
    String command = args[0];
    String[] rest = java.util.Arrays.copyOfRange(args, 1, args.length);
    try {
      if (command.equals("simplify")) {
        return SimplifyCommand.run(rest, out, err);
      }
      if (command.equals("send")) {
        return SendCommand.run(rest, out, err);
      }
      err.println(
          "Error: command: invalid choice: '"
              + command
              + "' (choose from 'simplify', 'send'). See '"
              + PROG
              + " --help'.");
      return 2;
    } catch (UsageException usage) {
      // As the reference's parser: one line, "argument " dropped, where to read more.
      String text = String.join(" ", usage.getMessage().strip().split("\\s+"));
      while (text.endsWith(".")) {
        text = text.substring(0, text.length() - 1);
      }
      text = text.replaceFirst("^argument (?=\\S+: )", "");
      err.println("Error: " + text + ". See '" + usage.prog + " --help'.");
      return 2;
    } catch (IllegalArgumentException | java.io.UncheckedIOException error) {
      err.println("Error: " + error.getMessage());
      return 1;
    } catch (RuntimeException bug) {
      String detail = String.join(" ", String.valueOf(bug.getMessage()).split("\\s+"));
      err.println(
          "Error: an internal error ("
              + bug.getClass().getSimpleName()
              + ": "
              + detail.substring(0, Math.min(300, detail.length()))
              + "); please report it with the command you ran.");
      return 70;
    }
  }

  /** A usage error: the command line itself is wrong (exit 2). */
  static final class UsageException extends RuntimeException {
    private static final long serialVersionUID = 1L;
    final String prog;

    UsageException(String prog, String message) {
      super(message);
      this.prog = prog;
    }
  }
}
