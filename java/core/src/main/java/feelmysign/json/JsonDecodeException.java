package feelmysign.json;

/**
 * Text that is not JSON, as Python's {@code json.JSONDecodeError} reports it: the message
 * ({@code msg}), and the line and column (from 1, in Unicode code points) where it was found.
 * A document nested too deeply has no position (Python's RecursionError).
 */
public final class JsonDecodeException extends IllegalArgumentException {
  private static final long serialVersionUID = 1L;

  private final String msg;
  private final int position;
  private final int line;
  private final int column;

  JsonDecodeException(String msg, String document, int charIndex) {
    super(msg);
    this.msg = msg;
    if (charIndex < 0) {
      this.position = -1;
      this.line = 0;
      this.column = 0;
      return;
    }
    // Python counts code points; a Java String counts UTF-16 units.
    int pos = document.codePointCount(0, Math.min(charIndex, document.length()));
    int lineCount = 1;
    int lastNewline = -1;
    int codePoint = 0;
    for (int i = 0; i < charIndex && i < document.length(); ) {
      int c = document.codePointAt(i);
      if (c == '\n') {
        lineCount++;
        lastNewline = codePoint;
      }
      codePoint++;
      i += Character.charCount(c);
    }
    this.position = pos;
    this.line = lineCount;
    this.column = pos - lastNewline;
  }

  /** The message without its position, e.g. "Expecting value". */
  public String msg() {
    return msg;
  }

  /** Whether the text was nested too deeply to read (no position). */
  public boolean tooDeep() {
    return position < 0;
  }

  public int line() {
    return line;
  }

  public int column() {
    return column;
  }

  /** Where, in Unicode code points from 0. */
  public int position() {
    return position;
  }

  /** As Python's {@code str(JSONDecodeError)}: "msg: line L column C (char P)". */
  @Override
  public String getMessage() {
    if (position < 0) {
      return msg;
    }
    return msg + ": line " + line + " column " + column + " (char " + position + ")";
  }
}
