/**
 * Strokes not yet acknowledged by the broker. A stroke drawn while offline
 * waits here and goes out, in order, on reconnect; one published but not yet
 * acknowledged (QoS 1) stays counted until its PUBACK. Nothing is dropped
 * silently: `size` is what the page shows as "unsent".
 */
export interface OutboxEntry<T> {
  readonly id: number;
  readonly item: T;
  /** When it was added (performance.now() ms): how long it has waited. */
  readonly added_ms: number;
}

export class Outbox<T> {
  #queued: OutboxEntry<T>[] = [];
  readonly #inFlight = new Map<number, OutboxEntry<T>>();
  #nextId = 0;

  add(item: T, nowMs: number = performance.now()): void {
    this.#queued.push({ id: this.#nextId++, item, added_ms: nowMs });
  }

  /** Queued plus in flight: every stroke the sleeve may not have yet. */
  get size(): number {
    return this.#queued.length + this.#inFlight.size;
  }

  get queuedCount(): number {
    return this.#queued.length;
  }

  /** Every queued entry, oldest first, now counted as in flight. */
  takeQueued(): OutboxEntry<T>[] {
    const taken = this.#queued;
    this.#queued = [];
    for (const entry of taken) this.#inFlight.set(entry.id, entry);
    return taken;
  }

  /** The broker acknowledged it: gone for good. */
  ack(id: number): void {
    this.#inFlight.delete(id);
  }

  /** Publishing failed: back in the queue, in its original order. */
  fail(id: number): void {
    const entry = this.#inFlight.get(id);
    if (entry === undefined) return;
    this.#inFlight.delete(id);
    this.#queued.push(entry);
    this.#queued.sort((a, b) => a.id - b.id);
  }

  /** Removes the queued (not in flight) entries `drop` picks; returns their items. */
  dropQueued(drop: (item: T, entry: OutboxEntry<T>) => boolean): T[] {
    const dropped = this.#queued.filter((entry) => drop(entry.item, entry)).map((entry) => entry.item);
    this.#queued = this.#queued.filter((entry) => !drop(entry.item, entry));
    return dropped;
  }

  /** A new connection replaces the old one: everything in flight is sent again. */
  requeueInFlight(): void {
    if (this.#inFlight.size === 0) return;
    // One sort for all of them: a thousand strokes kept offline come back at once.
    for (const entry of this.#inFlight.values()) this.#queued.push(entry);
    this.#inFlight.clear();
    this.#queued.sort((a, b) => a.id - b.id);
  }
}
