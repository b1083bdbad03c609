package feelmysign.cli;

import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * Numbers on the command line as the reference's command line reads them: decimal digits only
 * (ASCII), whitespace around allowed; not Python's {@code 1_000}, {@code inf} or {@code nan}.
 */
final class PythonNumbers {
  private PythonNumbers() {}

  // Python's \s is Unicode whitespace: (?U) makes Java's the same.
  private static final Pattern DECIMAL =
      Pattern.compile("(?U)\\s*([+-]?(?:[0-9]+(?:\\.[0-9]*)?|\\.[0-9]+)(?:[eE][+-]?[0-9]+)?)\\s*");
  private static final Pattern WHOLE = Pattern.compile("(?U)\\s*([+-]?[0-9]+)\\s*");

  /** A number written in decimal (1, 0.5, .5, 2e-3), or null. */
  static Double parseFloat(String text) {
    Matcher m = DECIMAL.matcher(text);
    return m.matches() ? Double.parseDouble(m.group(1)) : null;
  }

  /** A whole number written in decimal digits, or null (also for one beyond a long). */
  static Long parseInt(String text) {
    Matcher m = WHOLE.matcher(text);
    if (!m.matches()) {
      return null;
    }
    try {
      return Long.parseLong(m.group(1));
    } catch (NumberFormatException tooLarge) {
      return null;
    }
  }
}
