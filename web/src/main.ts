/** Entry point: read the server's config, then start the client. */
import "./styles.css";
import { App } from "./app";
import { fetchConfig } from "./config";
import { memoryStorage } from "./memory-storage";
import { buildToolbar } from "./ui/toolbar";

declare global {
  interface Window {
    /** The running client, for the browser tests and the benchmark. */
    feelmysign?: App;
  }
}

/** Settings survive a reload in localStorage; where it is blocked they last for the visit. */
function settingsStorage(): Storage {
  try {
    const probe = "feelmysign.probe";
    localStorage.setItem(probe, probe);
    localStorage.removeItem(probe);
    return localStorage;
  } catch {
    return memoryStorage();
  }
}

// The toolbar first: its place is taken before the config arrives, so nothing moves then.
const toolbar = document.getElementById("toolbar");
if (toolbar !== null) buildToolbar(toolbar);
const { config, note } = await fetchConfig();
window.feelmysign = new App(document, { config, configNote: note, storage: settingsStorage() });
