/**
 * The drawing toolbar, built from one table: every button has the same parts
 * (an icon, a label, a tooltip, an id the page and the tests find it by), so
 * they are written once here instead of six times in index.html.
 */

interface Tool {
  /** The button's id is `${name}-button`, and so is its data-testid. */
  readonly name: string;
  readonly label: string;
  readonly title: string;
  /** The icon's SVG content (a 24 x 24 viewBox, stroked in the text colour). */
  readonly icon: string;
  /** Disabled until there is a drawing to act on. */
  readonly needsDrawing?: boolean;
  readonly stop?: boolean;
}

const TOOLS: readonly Tool[] = [
  {
    name: "new",
    label: "New drawing",
    title: "Start a new, empty drawing",
    icon: '<path d="M12 5v14M5 12h14" />',
  },
  {
    name: "undo",
    label: "Undo path",
    title: "Take back the last path drawn",
    icon: '<path d="M9 7 4 12l5 5M4 12h11a5 5 0 0 1 0 10h-2" />',
    needsDrawing: true,
  },
  {
    name: "stop",
    label: "Stop",
    title: "Stop the sleeve now: every motor off, the rest of this drawing dropped (Esc)",
    icon: '<rect x="6" y="6" width="12" height="12" rx="2" />',
    stop: true,
  },
  {
    name: "replay",
    label: "Play again",
    title: "Send the same strokes again",
    icon: '<path d="M7 5v14l12-7z" />',
    needsDrawing: true,
  },
  {
    name: "record",
    label: "Save",
    title: "Save this drawing as a recording (Load reads it back; feelmysign simplify reads it too)",
    icon: '<path d="M12 4v11m-5-5 5 5 5-5M5 20h14" />',
    needsDrawing: true,
  },
  {
    name: "load",
    label: "Load",
    title: "Load a saved recording: see what would be felt, then Play again",
    icon: '<path d="M12 15V4m-5 5 5-5 5 5M5 20h14" />',
  },
];

/** Fills `toolbar` with the drawing's buttons, in order, before anything looks them up. */
export function buildToolbar(toolbar: HTMLElement): void {
  toolbar.prepend(
    ...TOOLS.map((tool) => {
      const button = document.createElement("button");
      button.type = "button";
      button.className = tool.stop ? "button button-stop" : "button";
      button.id = `${tool.name}-button`;
      button.dataset["testid"] = button.id;
      button.title = tool.title;
      button.disabled = tool.needsDrawing === true;
      // Static markup from the table above: no text from outside ever reaches innerHTML.
      button.innerHTML =
        `<svg viewBox="0 0 24 24" aria-hidden="true">${tool.icon}</svg>` +
        `<span>${tool.label}</span>${tool.stop ? "<kbd>Esc</kbd>" : ""}`;
      return button;
    }),
  );
}
