import { fileURLToPath } from "node:url";
import type { Plugin } from "vite";
import { defineConfig } from "vitest/config";

const repoRoot = fileURLToPath(new URL("..", import.meta.url));

/** The brand's dot, as the pages' icon. */
const ICON =
  "data:image/svg+xml,%3Csvg xmlns='http://www.w3.org/2000/svg' viewBox='0 0 16 16'%3E" +
  "%3Ccircle cx='8' cy='8' r='6' fill='%23ff8a5b'/%3E%3C/svg%3E";

/** What the head of every page has (charset, colour, icon): written once, added to each page. */
const sharedHead: Plugin = {
  name: "feelmysign-shared-head",
  transformIndexHtml: () => [
    { tag: "meta", attrs: { charset: "utf-8" }, injectTo: "head-prepend" },
    { tag: "meta", attrs: { name: "theme-color", content: "#0e141b" }, injectTo: "head" },
    { tag: "link", attrs: { rel: "icon", href: ICON }, injectTo: "head" },
  ],
};

export default defineConfig({
  // Relative asset paths: `feelmysign up` may serve dist/ under any prefix.
  base: "./",
  plugins: [sharedHead],
  server: {
    host: "127.0.0.1",
    // The settings import testdata/angle/params.json from outside web/.
    fs: { allow: [repoRoot] },
  },
  build: {
    outDir: "dist",
    emptyOutDir: true,
    target: "es2022",
    // Three pages: the drawing client, the researcher's study page (served at /study) and the
    // wearer's page (served at /wearer).
    rollupOptions: {
      input: {
        main: fileURLToPath(new URL("index.html", import.meta.url)),
        study: fileURLToPath(new URL("study.html", import.meta.url)),
        wearer: fileURLToPath(new URL("wearer.html", import.meta.url)),
      },
    },
  },
  test: {
    include: ["test/**/*.test.ts"],
    environment: "node",
    // Not vitest's 5 s: a property test that takes 0.7 s here may take seconds on a busy machine.
    testTimeout: 60_000,
  },
});
