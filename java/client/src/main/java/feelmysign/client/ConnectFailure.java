package feelmysign.client;

import com.hivemq.client.mqtt.exceptions.ConnectionClosedException;
import java.net.ConnectException;
import java.net.SocketTimeoutException;
import java.net.UnknownHostException;

/**
 * Why a connection to a broker failed, as a sentence a person can act on: the reference's
 * sentences (python/src/feelmysign/connection/failures.py), never an exception's class name.
 */
public final class ConnectFailure {
  private ConnectFailure() {}

  /** What a program's user gives the broker as: a sketch's broker(url), a client's URL. */
  private static final String GIVEN_AS = "broker URL";

  /** What to do when no broker is there, as the reference says it ("--broker URL"). */
  public static String startHint(String givenAs) {
    return "start one with 'feelmysign broker' or 'make up', or give the right " + givenAs;
  }

  /** Nothing listens on the broker's port; {@code givenAs}: what the URL was given as. */
  public static String refused(String url, String givenAs) {
    return "Nothing accepts connections at " + url + " (connection refused): "
        + startHint(givenAs) + ".";
  }

  /** The broker's host name is not known; {@code where}: where it was given ("--broker"). */
  public static String unknownHost(String url, String host, String where) {
    return "Cannot find the host '" + host + "' of " + url + ": check the host name in "
        + where + ".";
  }

  /**
   * Why connecting to {@code url} failed, from the error the MQTT client gave (or null: the
   * connection closed).
   */
  public static String sentence(BrokerUrl broker, Throwable failure) {
    String url = broker.toString();
    String host = broker.host();
    for (Throwable t = failure; t != null; t = t.getCause()) {
      if (t instanceof ConnectException) {
        return refused(url, GIVEN_AS);
      }
      if (t instanceof UnknownHostException) {
        return unknownHost(url, host, "the " + GIVEN_AS);
      }
      if (t instanceof SocketTimeoutException
          || t.getClass().getSimpleName().equals("ConnectTimeoutException")) {
        return "No answer from " + url + ": check the host and port, the network and any"
            + " firewall; or " + startHint(GIVEN_AS) + ".";
      }
    }
    if (failure == null || failure instanceof ConnectionClosedException) {
      String kind = broker.webSocket() ? "WebSocket" : "TCP";
      return url + " closed the connection before answering the login: is that port an MQTT"
          + " broker's " + kind + " listener? (The local broker's ports are in its"
          + " credentials.json.)";
    }
    return "Cannot connect to " + url + " (" + detail(failure) + "): check the " + GIVEN_AS + ", or "
        + startHint(GIVEN_AS) + ".";
  }

  /** The innermost message, without the class names Netty and HiveMQ put in front of it. */
  static String detail(Throwable failure) {
    Throwable root = failure;
    while (root.getCause() != null && root.getCause() != root) {
      root = root.getCause();
    }
    String message = root.getMessage();
    if (message == null || message.isBlank()) {
      return "no detail";
    }
    // "io.netty.channel.AbstractChannel$AnnotatedConnectException: Connection refused: ..."
    return message.replaceAll("(?:[a-z][\\w]*\\.)+[A-Z][\\w$]*(?:Exception|Error): ", "").strip();
  }
}
