package feelmysign.protocol;

import feelmysign.json.JsonKind;
import feelmysign.json.PyDumps;
import feelmysign.json.PyRepr;
import java.math.BigInteger;
import java.util.List;
import java.util.Map;

/** How the reference quotes values in its messages: cut, escaped, with their JSON kind. */
final class Text {
  private Text() {}

  /** Bad values are quoted in messages up to this many characters. */
  static final int SHOWN_VALUE_CHARS = 40;

  /** {@code text} cut to 40 characters (code points, as Python counts), "..." after a cut. */
  static String cut(String text) {
    if (text.codePointCount(0, text.length()) <= SHOWN_VALUE_CHARS) {
      return text;
    }
    return text.substring(0, text.offsetByCodePoints(0, SHOWN_VALUE_CHARS)) + "...";
  }

  /** {@code text} quoted for a message, cut, control characters escaped. */
  static String showText(String text) {
    if (text.codePointCount(0, text.length()) <= SHOWN_VALUE_CHARS) {
      return PyDumps.dumpsUnicode(text);
    }
    String head = text.substring(0, text.offsetByCodePoints(0, SHOWN_VALUE_CHARS));
    return PyDumps.dumpsUnicode(head) + "...";
  }

  /** A JSON value and its kind, for wrong_type messages: '"0,0" (a string)'. */
  static String described(Object value) {
    return value == null ? "null" : showJson(value) + " (" + jsonKind(value) + ")";
  }

  static String showJson(Object value) {
    return cut(PyDumps.dumpsUnicode(value));
  }

  static String jsonKind(Object value) {
    return JsonKind.of(value);
  }

  /** Python's {@code str()} of a JSON number: "2", "2.5", "1e+16". */
  static String pythonStr(Object number) {
    if (number instanceof Double d) {
      return feelmysign.json.Numbers.pythonRepr(d);
    }
    if (number instanceof Long || number instanceof BigInteger || number instanceof Integer) {
      return number.toString();
    }
    return String.valueOf(number);
  }

  /**
   * Python's {@code difflib.get_close_matches(word, possibilities, n=1, cutoff=0.6)}: the
   * possibility most like {@code word} (by SequenceMatcher's ratio, ties to the greater string),
   * or null when none reaches the cutoff.
   */
  static String closeMatch(String word, Iterable<String> possibilities, double cutoff) {
    int[] b = word.codePoints().toArray();
    String best = null;
    double bestRatio = -1;
    for (String possibility : possibilities) {
      int[] a = possibility.codePoints().toArray();
      double ratio = ratio(a, b);
      if (ratio < cutoff) {
        continue;
      }
      if (ratio > bestRatio || (ratio == bestRatio && compareCodePoints(possibility, best) > 0)) {
        best = possibility;
        bestRatio = ratio;
      }
    }
    return best;
  }

  private static int compareCodePoints(String left, String right) {
    int[] l = left.codePoints().toArray();
    int[] r = right.codePoints().toArray();
    for (int i = 0; i < Math.min(l.length, r.length); i++) {
      if (l[i] != r[i]) {
        return Integer.compare(l[i], r[i]);
      }
    }
    return Integer.compare(l.length, r.length);
  }

  /** SequenceMatcher(None, a, b).ratio() for a short b (no junk, no popular elements). */
  private static double ratio(int[] a, int[] b) {
    int total = a.length + b.length;
    if (total == 0) {
      return 1.0;
    }
    return 2.0 * matches(a, 0, a.length, b, 0, b.length) / total;
  }

  /** The characters of get_matching_blocks: the longest match, then the same on each side. */
  private static int matches(int[] a, int alo, int ahi, int[] b, int blo, int bhi) {
    int besti = alo;
    int bestj = blo;
    int bestsize = 0;
    // j2len[j + 1]: length of the match ending at a[i - 1], b[j]; rows for i - 1 and i.
    int[] previous = new int[b.length + 1];
    int[] current = new int[b.length + 1];
    for (int i = alo; i < ahi; i++) {
      java.util.Arrays.fill(current, 0);
      for (int j = blo; j < bhi; j++) {
        if (a[i] == b[j]) {
          int k = previous[j] + 1;
          current[j + 1] = k;
          if (k > bestsize) {
            besti = i - k + 1;
            bestj = j - k + 1;
            bestsize = k;
          }
        }
      }
      int[] swap = previous;
      previous = current;
      current = swap;
    }
    if (bestsize == 0) {
      return 0;
    }
    int sum = bestsize;
    if (alo < besti && blo < bestj) {
      sum += matches(a, alo, besti, b, blo, bestj);
    }
    if (besti + bestsize < ahi && bestj + bestsize < bhi) {
      sum += matches(a, besti + bestsize, ahi, b, bestj + bestsize, bhi);
    }
    return sum;
  }
}
