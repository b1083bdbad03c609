package feelmysign.protocol;

/** The two formats on the wire: the paper's legacy text and JSON v1. */
public enum WireFormat {
  /** {@code startX,startY,endX,endY,duration}, the paper's sleeve (appendix A.2). */
  LEGACY,
  /** {@code {"v":1,"start":[x,y],"end":[x,y],"duration_ms":d,...}}. */
  JSON;

  /** The name used in documents and vectors: "legacy" or "json". */
  public String wireName() {
    return name().toLowerCase(java.util.Locale.ROOT);
  }
}
