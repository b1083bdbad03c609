package feelmysign.cli;

import java.util.ArrayList;
import java.util.List;
import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * A command's {@code --help} laid out as the reference's parser (Python 3's argparse) lays it
 * out, so the two ports' help reads the same: the usage wrapped after the program's name, the
 * description filled, then each argument with its help beside it from column 24. The width is
 * {@code $COLUMNS} less 2, else 78, as argparse's own.
 */
final class ArgparseHelp {
  /** One argument: its invocation ("--max-error UNITS", "-h, --help"), its usage part
   * ("[--max-error UNITS]", "RECORDING") and its help. */
  record Argument(String invocation, String usagePart, String help, boolean positional) {}

  private static final String PREFIX = "usage: ";
  private static final int MAX_HELP_POSITION = 24;
  // argparse's part of a usage line: a bracketed optional, or a word.
  private static final Pattern USAGE_PART =
      Pattern.compile("\\(.*?\\)+(?=\\s|$)|\\[.*?\\]+(?=\\s|$)|\\S+");

  private final String prog;
  private final String description;
  private final List<Argument> arguments;
  private final int width;

  ArgparseHelp(String prog, String description, List<Argument> arguments) {
    this(prog, description, arguments, terminalWidth());
  }

  ArgparseHelp(String prog, String description, List<Argument> arguments, int width) {
    this.prog = prog;
    this.description = description;
    this.arguments = List.copyOf(arguments);
    this.width = width;
  }

  /** shutil.get_terminal_size()'s columns, less 2: $COLUMNS when it is a positive number,
   * else 80 (what Python falls back to when its output is not a terminal). */
  static int terminalWidth() {
    String columns = System.getenv("COLUMNS");
    try {
      int value = columns == null ? 0 : Integer.parseInt(columns.strip());
      return (value > 0 ? value : 80) - 2;
    } catch (NumberFormatException notANumber) {
      return 80 - 2;
    }
  }

  /** The usage block, "usage: PROG [-h] ...", without a trailing newline. */
  String usage() {
    List<String> optional = new ArrayList<>();
    List<String> positional = new ArrayList<>();
    for (Argument argument : arguments) {
      (argument.positional() ? positional : optional).add(argument.usagePart());
    }
    String optionalUsage = String.join(" ", optional);
    String positionalUsage = String.join(" ", positional);
    String actions = String.join(" ", nonEmpty(optionalUsage, positionalUsage));
    String all = String.join(" ", nonEmpty(prog, actions));
    if (PREFIX.length() + all.length() <= width) {
      return PREFIX + all;
    }
    List<String> optParts = parts(optionalUsage);
    List<String> posParts = parts(positionalUsage);
    List<String> lines;
    if (PREFIX.length() + prog.length() <= 0.75 * width) {
      String indent = " ".repeat(PREFIX.length() + prog.length() + 1);
      List<String> first = new ArrayList<>(List.of(prog));
      if (!optParts.isEmpty()) {
        first.addAll(optParts);
        lines = lines(first, indent, true);
        lines.addAll(lines(posParts, indent, false));
      } else if (!posParts.isEmpty()) {
        first.addAll(posParts);
        lines = lines(first, indent, true);
      } else {
        lines = new ArrayList<>(first);
      }
    } else {
      String indent = " ".repeat(PREFIX.length());
      List<String> both = new ArrayList<>(optParts);
      both.addAll(posParts);
      lines = lines(both, indent, false);
      if (lines.size() > 1) {
        lines = lines(optParts, indent, false);
        lines.addAll(lines(posParts, indent, false));
      }
      lines.add(0, prog);
    }
    return PREFIX + String.join("\n", lines);
  }

  /** The whole help, ending in one newline. */
  String help() {
    StringBuilder out = new StringBuilder(usage()).append("\n\n");
    out.append(String.join("\n", wrap(description, Math.max(width, 11)))).append("\n\n");
    int longest = 0;
    for (Argument argument : arguments) {
      longest = Math.max(longest, argument.invocation().length() + 2);
    }
    int maxHelpPosition = Math.min(MAX_HELP_POSITION, Math.max(width - 20, 4));
    int helpPosition = Math.min(longest + 2, maxHelpPosition);
    section(out, "positional arguments", true, helpPosition);
    out.append('\n');
    section(out, "options", false, helpPosition);
    return out.toString();
  }

  private void section(StringBuilder out, String heading, boolean positional, int helpPosition) {
    out.append(heading).append(":\n");
    int helpWidth = Math.max(width - helpPosition, 11);
    int actionWidth = helpPosition - 2 - 2;
    for (Argument argument : arguments) {
      if (argument.positional() != positional) {
        continue;
      }
      List<String> help = wrap(argument.help(), helpWidth);
      String invocation = "  " + argument.invocation();
      int first;
      if (argument.invocation().length() <= actionWidth) {
        out.append(String.format("%-" + helpPosition + "s", invocation));
        first = 0;
      } else {
        out.append(invocation).append('\n');
        first = helpPosition;
      }
      for (int i = 0; i < help.size(); i++) {
        out.append(" ".repeat(i == 0 ? first : helpPosition)).append(help.get(i)).append('\n');
      }
    }
  }

  private static List<String> nonEmpty(String... texts) {
    List<String> out = new ArrayList<>();
    for (String text : texts) {
      if (!text.isEmpty()) {
        out.add(text);
      }
    }
    return out;
  }

  private static List<String> parts(String usage) {
    List<String> out = new ArrayList<>();
    Matcher m = USAGE_PART.matcher(usage);
    while (m.find()) {
      out.add(m.group());
    }
    return out;
  }

  /** argparse's get_lines: the parts joined by spaces, a new (indented) line when one is full. */
  private List<String> lines(List<String> parts, String indent, boolean afterPrefix) {
    List<String> lines = new ArrayList<>();
    List<String> line = new ArrayList<>();
    int lineLength = (afterPrefix ? PREFIX.length() : indent.length()) - 1;
    for (String part : parts) {
      if (lineLength + 1 + part.length() > width && !line.isEmpty()) {
        lines.add(indent + String.join(" ", line));
        line.clear();
        lineLength = indent.length() - 1;
      }
      line.add(part);
      lineLength += part.length() + 1;
    }
    if (!line.isEmpty()) {
      lines.add(indent + String.join(" ", line));
    }
    if (afterPrefix && !lines.isEmpty()) {
      lines.set(0, lines.get(0).substring(indent.length()));
    }
    return lines;
  }

  // --- textwrap.wrap, with its defaults ------------------------------------------------------

  // textwrap's TextWrapper.wordsep_re: whitespace, an em-dash between words, or a word up to
  // the end of a hyphenated part (so "error-bounded" may break after "error-").
  private static final String WS = "[\\t\\n\\x0b\\x0c\\r ]";
  private static final String NWS = "[^\\t\\n\\x0b\\x0c\\r ]";
  private static final String WP = "[\\w!\"'&.,?]";
  private static final String LT = "[^\\d\\W]";
  private static final Pattern WORD_SEPARATOR =
      Pattern.compile(
          "("
              + WS + "+"
              + "|(?<=" + WP + ")-{2,}(?=\\w)"
              + "|" + NWS + "+?(?:"
              + "-(?:(?<=" + LT + "{2}-)|(?<=" + LT + "-" + LT + "-))(?=" + LT + "-?" + LT + ")"
              + "|(?=" + WS + "|\\z)"
              + "|(?<=" + WP + ")(?=-{2,}\\w)"
              + "))",
          Pattern.UNICODE_CHARACTER_CLASS);
  private static final Pattern WHITESPACE = Pattern.compile("[ \\t\\n\\r\\f\\x0b]+");

  /** argparse's _split_lines: whitespace runs made one space, then textwrap.wrap(text, width). */
  static List<String> wrap(String text, int width) {
    String normalized = WHITESPACE.matcher(text).replaceAll(" ").strip();
    List<String> chunks = new ArrayList<>();
    Matcher m = WORD_SEPARATOR.matcher(normalized);
    int end = 0;
    while (m.find()) {
      if (m.start() > end) {
        chunks.add(normalized.substring(end, m.start()));
      }
      if (!m.group().isEmpty()) {
        chunks.add(m.group());
      }
      end = m.end();
    }
    if (end < normalized.length()) {
      chunks.add(normalized.substring(end));
    }
    List<String> lines = new ArrayList<>();
    int next = 0;
    while (next < chunks.size()) {
      if (!lines.isEmpty() && chunks.get(next).isBlank()) {
        next++;
        continue;
      }
      List<String> line = new ArrayList<>();
      int length = 0;
      while (next < chunks.size() && length + chunks.get(next).length() <= width) {
        length += chunks.get(next).length();
        line.add(chunks.get(next++));
      }
      if (next < chunks.size() && chunks.get(next).length() > width) {
        // A word longer than a line: cut it, after a hyphen if one fits.
        String chunk = chunks.get(next);
        int room = width - length;
        int cut = room;
        int hyphen = chunk.lastIndexOf('-', room - 1);
        if (chunk.length() > room && hyphen > 0 && !chunk.substring(0, hyphen).matches("-*")) {
          cut = hyphen + 1;
        }
        line.add(chunk.substring(0, cut));
        chunks.set(next, chunk.substring(cut));
      }
      if (!line.isEmpty() && line.get(line.size() - 1).isBlank()) {
        line.remove(line.size() - 1);
      }
      if (!line.isEmpty()) {
        lines.add(String.join("", line));
      }
    }
    return lines;
  }
}
