/** Reads the shared vectors in ../testdata (written by the Python reference; never pasted here). */
import { readdirSync, readFileSync, statSync } from "node:fs";
import { join, relative } from "node:path";
import { fileURLToPath } from "node:url";

export const TESTDATA_DIR = fileURLToPath(new URL("../../testdata", import.meta.url));

/** Every .json file under testdata/<part>/<sub>, as [name relative to testdata, parsed JSON]. */
export function vectors(part: string, sub?: string): [string, unknown][] {
  const root = join(TESTDATA_DIR, part, ...(sub === undefined ? [] : [sub]));
  const files: string[] = [];
  const walk = (dir: string): void => {
    for (const name of readdirSync(dir).sort()) {
      const path = join(dir, name);
      if (statSync(path).isDirectory()) walk(path);
      else if (name.endsWith(".json")) files.push(path);
    }
  };
  walk(root);
  return files.map((path) => [relative(TESTDATA_DIR, path), JSON.parse(readFileSync(path, "utf8"))]);
}

export function hasVectors(part: string, sub?: string): boolean {
  try {
    return statSync(join(TESTDATA_DIR, part, ...(sub === undefined ? [] : [sub]))).isDirectory();
  } catch {
    return false;
  }
}
