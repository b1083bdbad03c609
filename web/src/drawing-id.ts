/**
 * A new drawing's id: a random UUID (v4). `crypto.randomUUID` exists only in
 * secure contexts (https, localhost); a phone opening the page over plain http
 * on the local network still gets one from `crypto.getRandomValues`.
 */
export function newDrawingId(source: Crypto = crypto): string {
  if (typeof source.randomUUID === "function") {
    try {
      return source.randomUUID();
    } catch {
      // Not a secure context: fall through.
    }
  }
  const bytes = source.getRandomValues(new Uint8Array(16));
  bytes[6] = (bytes[6]! & 0x0f) | 0x40; // version 4
  bytes[8] = (bytes[8]! & 0x3f) | 0x80; // RFC 4122 variant
  const hex = Array.from(bytes, (byte) => byte.toString(16).padStart(2, "0")).join("");
  return `${hex.slice(0, 8)}-${hex.slice(8, 12)}-${hex.slice(12, 16)}-${hex.slice(16, 20)}-${hex.slice(20)}`;
}
