package feelmysign.client;

import java.net.URI;
import java.net.URISyntaxException;
import java.util.Locale;

/**
 * Where the broker is: {@code mqtt://host:port} (TCP), {@code mqtts://} (TLS), {@code ws://} or
 * {@code wss://} (WebSockets, plain or over TLS, with a path). The default ports are MQTT's:
 * 1883, 8883, 80 and 443.
 */
public record BrokerUrl(String scheme, String host, int port, String path) {

  /**
   * Read a broker URL.
   *
   * @throws IllegalArgumentException naming what is wrong and what a URL looks like
   */
  public static BrokerUrl parse(String url) {
    String example = " (e.g. mqtt://127.0.0.1:1883, mqtts://sleeve.local:8883 or ws://host:9001)";
    URI uri;
    try {
      uri = new URI(url.strip());
    } catch (URISyntaxException | NullPointerException error) {
      throw new IllegalArgumentException("broker URL " + quoted(url) + " is not a URL" + example);
    }
    String scheme = uri.getScheme() == null ? "" : uri.getScheme().toLowerCase(Locale.ROOT);
    int defaultPort =
        switch (scheme) {
          case "mqtt", "tcp" -> 1883;
          case "mqtts", "ssl" -> 8883;
          case "ws" -> 80;
          case "wss" -> 443;
          default -> throw new IllegalArgumentException(
              "broker URL "
                  + quoted(url)
                  + " must start with mqtt://, mqtts://, ws:// or wss://"
                  + example);
        };
    if (uri.getHost() == null || uri.getHost().isEmpty()) {
      throw new IllegalArgumentException("broker URL " + quoted(url) + " has no host" + example);
    }
    int port = uri.getPort() == -1 ? defaultPort : uri.getPort();
    if (port < 1 || port > 65535) {
      throw new IllegalArgumentException(
          "broker URL " + quoted(url) + ": the port must be in 1..65535" + example);
    }
    String normalized = scheme.equals("tcp") ? "mqtt" : scheme.equals("ssl") ? "mqtts" : scheme;
    String path = uri.getRawPath() == null ? "" : uri.getRawPath();
    return new BrokerUrl(normalized, uri.getHost(), port, path);
  }

  /** Whether the connection is TLS (mqtts, wss). */
  public boolean tls() {
    return scheme.equals("mqtts") || scheme.equals("wss");
  }

  /** Whether MQTT runs over WebSockets (ws, wss). */
  public boolean webSocket() {
    return scheme.equals("ws") || scheme.equals("wss");
  }

  @Override
  public String toString() {
    return scheme + "://" + host + ":" + port + path;
  }

  private static String quoted(String text) {
    return "'" + text + "'";
  }
}
