/** The browser tests: real Chromium, real Mosquitto, the built page. Run after `vite build`. */
import { defineConfig } from "vitest/config";

export default defineConfig({
  test: {
    include: ["e2e/**/*.e2e.ts"],
    // A temporary $XDG_STATE_HOME for every process the tests start.
    globalSetup: ["e2e/global-setup.ts"],
    environment: "node",
    // One browser and one broker at a time: the machine has two cores.
    fileParallelism: false,
    // Generous, as every wait inside them: a loaded two-core machine starts Python, Mosquitto
    // and Chromium slowly. They pass in far less; only a failure waits this long.
    testTimeout: 180_000,
    hookTimeout: 180_000,
  },
});
