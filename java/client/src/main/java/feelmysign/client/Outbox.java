package feelmysign.client;

import java.util.ArrayList;
import java.util.Comparator;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.BiPredicate;

/**
 * Strokes not yet acknowledged by the broker (the page's {@code web/src/outbox.ts}). A stroke
 * drawn while offline waits here and goes out, in order, on reconnect; one published but not
 * yet acknowledged (QoS 1) stays counted until its PUBACK. Nothing is dropped silently:
 * {@link #size} is what "unsent" means. Not thread-safe: its owner holds a lock.
 */
final class Outbox<T> {
  /** One item, its order and when it was added (ms of a monotonic clock). */
  record Entry<T>(long id, T item, long addedMs) {}

  private List<Entry<T>> queued = new ArrayList<>();
  private final Map<Long, Entry<T>> inFlight = new LinkedHashMap<>();
  private long nextId;

  void add(T item, long nowMs) {
    queued.add(new Entry<>(nextId++, item, nowMs));
  }

  /** Queued plus in flight: every stroke the sleeve may not have yet. */
  int size() {
    return queued.size() + inFlight.size();
  }

  /** Every queued entry, oldest first, now counted as in flight. */
  List<Entry<T>> takeQueued() {
    List<Entry<T>> taken = queued;
    queued = new ArrayList<>();
    for (Entry<T> entry : taken) {
      inFlight.put(entry.id(), entry);
    }
    return taken;
  }

  /** The broker acknowledged it: gone for good. */
  void ack(long id) {
    inFlight.remove(id);
  }

  /** Publishing failed: back in the queue, in its original order. */
  void fail(long id) {
    Entry<T> entry = inFlight.remove(id);
    if (entry != null) {
      queued.add(entry);
      queued.sort(Comparator.comparingLong(Entry::id));
    }
  }

  /** Removes the queued (not in flight) entries {@code drop} picks; returns their items. */
  List<T> dropQueued(BiPredicate<T, Entry<T>> drop) {
    List<T> dropped = new ArrayList<>();
    List<Entry<T>> kept = new ArrayList<>();
    for (Entry<T> entry : queued) {
      if (drop.test(entry.item(), entry)) {
        dropped.add(entry.item());
      } else {
        kept.add(entry);
      }
    }
    queued = kept;
    return dropped;
  }

  /** A new connection replaces the old one: everything in flight is sent again. */
  void requeueInFlight() {
    if (inFlight.isEmpty()) {
      return;
    }
    queued.addAll(inFlight.values());
    inFlight.clear();
    queued.sort(Comparator.comparingLong(Entry::id));
  }
}
