package feelmysign.protocol;

/**
 * Every MQTT topic feelmysign uses, built in one place (as {@code topics.py} and
 * {@code web/src/mqtt/topics.ts}).
 *
 * <pre>
 * feelmysign/&lt;sleeve-id&gt;/strokes     JSON v1 strokes in (QoS 1)
 * feelmysign/&lt;sleeve-id&gt;/control     control messages in: cancel a drawing or everything (QoS 1)
 * feelmysign/&lt;sleeve-id&gt;/status      retained: online, layout, version (last will: offline)
 * feelmysign/&lt;sleeve-id&gt;/actuators   actuator intensities, for previews
 * feelmysign/&lt;sleeve-id&gt;/events      one message per stroke played, adjusted or rejected
 * deviceOne/line                     legacy text strokes (the paper's sleeve)
 * </pre>
 *
 * A sleeve id is one topic level: letters, digits, {@code _} and {@code -} only, so it can never
 * be a wildcard.
 */
public final class Topics {
  private Topics() {}

  public static final String TOPIC_ROOT = "feelmysign";
  /** The paper's sleeve (appendix A.2). */
  public static final String LEGACY_TOPIC = "deviceOne/line";
  public static final String STROKES = "strokes";
  public static final String CONTROL = "control";
  public static final String STATUS = "status";
  public static final String ACTUATORS = "actuators";
  public static final String EVENTS = "events";
  /** The telemetry a sleeve publishes. */
  public static final java.util.List<String> TELEMETRY_NAMES =
      java.util.List.of(STATUS, ACTUATORS, EVENTS);
  /** In an ACL or a subscription: every sleeve's topic of one kind. */
  public static final String ANY_SLEEVE = "+";

  /** {@code feelmysign/<sleeveId>/<name>}; {@code sleeveId} may be {@link #ANY_SLEEVE}. */
  public static String sleeveTopic(String sleeveId, String name) {
    return TOPIC_ROOT + "/" + sleeveId + "/" + name;
  }

  public static String strokesTopic(String sleeveId) {
    return sleeveTopic(sleeveId, STROKES);
  }

  public static String controlTopic(String sleeveId) {
    return sleeveTopic(sleeveId, CONTROL);
  }

  /** The topic of one kind of telemetry: {@link #STATUS}, {@link #ACTUATORS} or {@link #EVENTS}. */
  public static String telemetryTopic(String sleeveId, String name) {
    if (!TELEMETRY_NAMES.contains(name)) {
      throw new IllegalArgumentException(
          "telemetry is one of " + TELEMETRY_NAMES + ", not " + name);
    }
    return sleeveTopic(sleeveId, name);
  }
}
