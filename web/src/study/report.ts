/**
 * The analysis's report (report.md) as HTML for the Results tab, by markdown-it.
 *
 * Raw HTML in the Markdown is off (`html: false`): the report quotes participants'
 * answers and the design's names, and nothing in a study file may put markup or script
 * on the researcher's page; such text is shown escaped, as written. A figure is shown
 * only when it names a file of the analysis (`accuracy.png`), served by `figureUrl`;
 * any other image is replaced by its alt text. Wide tables scroll on their own.
 */
import MarkdownIt from "markdown-it";

/** A figure the analysis wrote: a plain file name in the results folder. */
const FIGURE_NAME = /^[\w.-]+\.png$/;

export function reportHtml(markdown: string, figureUrl: (name: string) => string): string {
  const md = new MarkdownIt({ html: false, linkify: false, typographer: false });
  const renderToken = md.renderer.renderToken.bind(md.renderer);
  md.renderer.rules.table_open = (tokens, index, options) =>
    `<div class="table-scroll">${renderToken(tokens, index, options)}`;
  md.renderer.rules.table_close = (tokens, index, options) => `${renderToken(tokens, index, options)}</div>`;
  md.renderer.rules.image = (tokens, index, options, env, self) => {
    const token = tokens[index]!;
    const name = String(token.attrGet("src") ?? "");
    const alt = self.renderInlineAsText(token.children ?? [], options, env);
    if (!FIGURE_NAME.test(name) || name.includes("..")) return md.utils.escapeHtml(alt);
    token.attrSet("src", figureUrl(name));
    token.attrSet("alt", alt);
    token.attrSet("data-testid", `figure-${name}`);
    return self.renderToken(tokens, index, options);
  };
  return md.render(markdown);
}
