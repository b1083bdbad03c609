package feelmysign.simplify;

/** A segment and the index of the path it came from. */
public record PathSegment(int path, Segment segment) {}
