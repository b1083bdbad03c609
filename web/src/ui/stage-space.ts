/**
 * The room the drawing area may take on the page, measured from the laid-out
 * page: on a desktop its column but for the legend under it; stacked (a
 * phone, a small window) the first screen from the area's top down.
 */
import { byId } from "./status";

/** The media query of styles.css under which the sleeve's cards go below the drawing area. */
const STACKED_LAYOUT = "(max-width: 820px), (max-height: 560px)";
/** The one of styles.css for a phone on its side: the toolbar beside the area, the legend below it all. */
const SHORT_LANDSCAPE = "(max-height: 560px) and (orientation: landscape)";
/** Stacked, below the area: the gap to the legend and the workspace's padding (styles.css). */
const STACKED_BELOW_PX = 10 + 12;
/** Stacked, the area is never squeezed below this height: the page scrolls instead. */
const STACKED_MIN_HEIGHT_PX = 240;

export class StageSpace {
  /** The box the stage is centred in: its width is the area's limit. */
  readonly area: HTMLElement;
  readonly #legend: HTMLElement;
  readonly #legendTurned: HTMLElement;

  constructor(doc: Document) {
    this.area = byId(doc, "stage-area");
    this.#legend = byId(doc, "legend");
    this.#legendTurned = byId(doc, "legend-turned");
  }

  /** The width and height the drawing area may take, CSS pixels. */
  available(): { widthPx: number; heightPx: number } {
    // The area takes its content's height, the legend right under it: the viewport (stacked,
    // phone) or the column (desktop) sets the limit.
    const stacked = window.matchMedia(STACKED_LAYOUT).matches;
    return {
      widthPx: this.area.clientWidth,
      heightPx: stacked ? this.#firstScreenHeight() : this.#columnHeight(),
    };
  }

  /** The legend's line that says the area is shown turned a quarter. */
  setTurned(turned: boolean): void {
    this.#legendTurned.hidden = !turned;
  }

  /** Stacked, the area fills the first screen: from its top to the window's bottom, the legend under it. */
  #firstScreenHeight(): number {
    const workspace = this.area.closest(".workspace");
    const top = this.area.getBoundingClientRect().top + (workspace?.scrollTop ?? 0) + window.scrollY;
    // A phone on its side keeps every pixel of height for drawing: the legend follows below the fold.
    const legend = window.matchMedia(SHORT_LANDSCAPE).matches ? 0 : this.#legendHeightTurned();
    return Math.max(STACKED_MIN_HEIGHT_PX, window.innerHeight - top - legend - STACKED_BELOW_PX);
  }

  /** Desktop, the area fills its column but for the legend, which follows it with no gap to fill. */
  #columnHeight(): number {
    const column = this.area.parentElement;
    if (!column) return this.area.clientHeight;
    const gap = parseFloat(getComputedStyle(column).rowGap) || 0;
    const bottom = column.getBoundingClientRect().bottom;
    const top = this.area.getBoundingClientRect().top;
    return Math.max(0, bottom - top - gap - this.#legendHeightTurned());
  }

  /**
   * The legend's height with its "turned" line shown, whether it is or not: the height left for
   * the area must not depend on the turn it decides, or a small phone would flip between the two.
   */
  #legendHeightTurned(): number {
    const line = this.#legendTurned;
    if (!line.hidden) return this.#legend.offsetHeight;
    line.hidden = false;
    const height = this.#legend.offsetHeight;
    line.hidden = true;
    return height;
  }
}
