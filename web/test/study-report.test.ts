/** The Results tab's report: report.md rendered as HTML, with nothing of a study file as markup. */
import { describe, expect, it } from "vitest";
import { reportHtml } from "../src/study/report";

// The shape of what `feelmysign study analyse` writes (python/src/feelmysign/study/analysis/report.py).
const REPORT = `# Pilot

2 participants (2 simulated), 16 measured trials.

## Accuracy by shape and resolution

| shape | coarse | fine |
|---|---|---|
| circle | 1/4 = 25% [5%, 70%] (4 strokes) | 4/4 = 100% [51%, 100%] (8 strokes) |
| square | 3/4 = 75% [30%, 95%] (4 strokes) | 4/4 = 100% [51%, 100%] (8 strokes) |

![accuracy](accuracy.png)

- first point
- second point

Files: trials.csv, results.json.
`;

const url = (name: string): string => `/api/study/results/${name}?t=1`;

describe("the report on the Results tab", () => {
  it("renders headings, tables, lists and figures, with no Markdown left", () => {
    const html = reportHtml(REPORT, url);
    expect(html).toContain("<h1>Pilot</h1>");
    expect(html).toContain("<h2>Accuracy by shape and resolution</h2>");
    expect(html).toMatch(/<div class="table-scroll"><table>\s*<thead>\s*<tr>\s*<th>shape<\/th>/);
    expect(html).toContain("<td>circle</td>");
    expect(html).toContain("<li>first point</li>");
    expect(html).toContain(
      '<img src="/api/study/results/accuracy.png?t=1" alt="accuracy" data-testid="figure-accuracy.png">',
    );
    expect(html).not.toContain("|---|");
    expect(html).not.toContain("![accuracy]");
  });

  it("shows HTML and script in a study file as text, never as markup", () => {
    const hostile = [
      "| shape | answer |",
      "|---|---|",
      '| <img src=x onerror="alert(1)"> | <script>alert(2)</script> |',
      "",
      "<iframe src='https://example.org'></iframe>",
      "",
      "[click](javascript:alert(3))",
    ].join("\n");
    const html = reportHtml(hostile, url);
    expect(html).not.toMatch(/<(script|iframe|img)\b/i);
    expect(html).toContain("&lt;script&gt;alert(2)&lt;/script&gt;");
    expect(html).not.toContain('href="javascript:');
  });

  it("shows only the analysis's own figures; any other image as its alt text", () => {
    const html = reportHtml(
      "![away](https://example.org/x.png) ![up](../secret.png) ![fine](needed-resolution.png)",
      url,
    );
    expect(html).toContain("away up ");
    expect(html.match(/<img /g)).toHaveLength(1);
    expect(html).toContain('src="/api/study/results/needed-resolution.png?t=1" alt="fine"');
  });
});
