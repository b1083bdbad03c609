/**
 * The settings panel in Chromium: the window simplifier's parameters that only one of its cores
 * reads (the table's `only_when`) are locked, with a note saying which core, while the Least
 * squares switch chooses the other core, and unlocked as soon as it is switched back; saved
 * settings lock them the same way when the panel opens again.
 */
import type { Locator, Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { openAdvanced, screenshot } from "./page";
import { DESKTOP, Processes } from "./processes";

/** Whether a row's controls are locked, and its note shown (null: hidden). */
async function state(page: Page, key: string): Promise<{ disabled: boolean; note: string | null }> {
  const input: Locator = page.locator(`[data-testid="setting-${key}"]`);
  const note = page.locator(`[data-testid="setting-${key}-note"]`);
  return {
    disabled: await input.isDisabled(),
    note: (await note.isVisible()) ? await note.innerText() : null,
  };
}

/** The simplifier's segmented control: a click on the choice's label, as a person clicks. */
async function chooseAlgorithm(page: Page, name: string): Promise<void> {
  const choice = page.locator(`[data-testid="setting-algorithm"][value="${name}"]`);
  await page.locator("label", { has: choice }).click();
  expect(await choice.isChecked()).toBe(true);
}

describe("settings read by one window core", () => {
  const processes = new Processes();
  let page: Page;

  beforeAll(async () => {
    const { url } = await processes.brokerAndPage("core-settings");
    page = await processes.page(url, { ...DESKTOP, deviceScaleFactor: 1 });
  });

  afterAll(() => processes.stop());

  it("locks the ones the other core reads, with a note, and unlocks them when switched", async () => {
    await page.locator('[data-testid="settings-button"]').click();
    await openAdvanced(page);
    const leastSquares = page.locator('[data-testid="setting-least_squares"]');
    expect(await leastSquares.isChecked()).toBe(true); // the default core
    const unlocked = { disabled: false, note: null };
    expect(await state(page, "lookahead_ms")).toEqual(unlocked);
    expect(await state(page, "max_bend")).toEqual({
      disabled: true,
      note: "Max bend: only with least squares off",
    });
    expect(await state(page, "bend_floor")).toEqual({
      disabled: true,
      note: "Bend floor: only with least squares off",
    });
    expect(await state(page, "max_error")).toEqual({ disabled: false, note: null });
    await page.locator('[data-field="max_bend"]').scrollIntoViewIfNeeded();
    await screenshot(page, "core-settings-least-squares");

    await leastSquares.setChecked(false);
    expect(await state(page, "lookahead_ms")).toEqual({
      disabled: true,
      note: "Lookahead: least squares only",
    });
    expect(await state(page, "max_bend")).toEqual(unlocked);
    expect(await state(page, "bend_floor")).toEqual(unlocked);
    await page.locator('[data-field="lookahead_ms"]').scrollIntoViewIfNeeded();
    await screenshot(page, "core-settings-chord");

    await leastSquares.setChecked(true);
    expect(await state(page, "lookahead_ms")).toEqual(unlocked);
    expect((await state(page, "max_bend")).disabled).toBe(true);
  });

  it("locks them by the saved switch when the panel opens again", async () => {
    await page.locator('[data-testid="setting-least_squares"]').setChecked(false);
    await page.locator('[data-testid="setting-max_bend"]').fill("0.2");
    expect(await page.locator('[data-testid="settings-save"]').isDisabled()).toBe(false);
    await page.locator('[data-testid="settings-save"]').click();
    await page.locator('[data-testid="settings-panel"]').waitFor({ state: "hidden" });
    await page.locator('[data-testid="settings-button"]').click();
    await openAdvanced(page);
    expect(await page.locator('[data-testid="setting-max_bend"]').inputValue()).toBe("0.2");
    expect(await state(page, "max_bend")).toEqual({ disabled: false, note: null });
    expect(await state(page, "lookahead_ms")).toEqual({
      disabled: true,
      note: "Lookahead: least squares only",
    });
  });

  it("shows no core note while the other simplifier is chosen (it locks them all)", async () => {
    await chooseAlgorithm(page, "angle");
    for (const key of ["lookahead_ms", "max_bend", "bend_floor"]) {
      expect(await state(page, key), key).toEqual({ disabled: true, note: null });
    }
    await chooseAlgorithm(page, "window");
    expect((await state(page, "lookahead_ms")).note).toBe("Lookahead: least squares only");
  });
});
