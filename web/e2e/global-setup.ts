/**
 * The browser tests' processes (`feelmysign up`, the sleeve, the broker) keep their state
 * ($XDG_STATE_HOME: wiring memos, default state directories) in a temporary directory of
 * the run, removed after it, never in the home directory of whoever runs the tests.
 */
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

export default function setup(): () => void {
  const stateHome = mkdtempSync(join(tmpdir(), "feelmysign-e2e-state-"));
  process.env["XDG_STATE_HOME"] = stateHome;
  return () => rmSync(stateHome, { recursive: true, force: true });
}
