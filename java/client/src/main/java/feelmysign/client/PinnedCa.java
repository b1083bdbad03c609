package feelmysign.client;

import io.netty.handler.ssl.util.SimpleTrustManagerFactory;
import java.security.GeneralSecurityException;
import java.security.KeyStore;
import java.security.MessageDigest;
import java.security.cert.CertificateException;
import java.security.cert.X509Certificate;
import java.util.HexFormat;
import java.util.Locale;
import javax.net.ssl.ManagerFactoryParameters;
import javax.net.ssl.TrustManager;
import javax.net.ssl.TrustManagerFactory;
import javax.net.ssl.X509TrustManager;

/**
 * Trust a broker's local CA by its fingerprint (SHA-256 of the certificate, 64 hex digits), as
 * a join token of {@code feelmysign broker} gives it: the CA is taken from the chain the broker
 * presents, only if its fingerprint is the one given, and the chain must then verify up to it
 * (the reference's {@code connection/pinned_ca.py}).
 */
final class PinnedCa extends SimpleTrustManagerFactory {
  private final String fingerprint;

  PinnedCa(String fingerprint) {
    String hex = fingerprint == null ? "" : fingerprint.strip().toLowerCase(Locale.ROOT);
    if (!hex.matches("[0-9a-f]{64}")) {
      throw new IllegalArgumentException(
          "a CA fingerprint is 64 hex digits (SHA-256), as in credentials.json's ca_fingerprint");
    }
    this.fingerprint = hex;
  }

  static String fingerprintOf(X509Certificate certificate) throws CertificateException {
    try {
      byte[] digest = MessageDigest.getInstance("SHA-256").digest(certificate.getEncoded());
      return HexFormat.of().formatHex(digest);
    } catch (GeneralSecurityException error) {
      throw new CertificateException(error);
    }
  }

  @Override
  protected void engineInit(KeyStore keyStore) {}

  @Override
  protected void engineInit(ManagerFactoryParameters parameters) {}

  @Override
  protected TrustManager[] engineGetTrustManagers() {
    return new TrustManager[] {new Pinned()};
  }

  private final class Pinned implements X509TrustManager {
    @Override
    public void checkServerTrusted(X509Certificate[] chain, String authType)
        throws CertificateException {
      X509Certificate ca = null;
      for (X509Certificate certificate : chain) {
        if (fingerprintOf(certificate).equals(fingerprint)) {
          ca = certificate;
        }
      }
      if (ca == null) {
        throw new CertificateException(
            "the broker's certificate chain has no CA with the fingerprint given (SHA-256 "
                + fingerprint.substring(0, 16)
                + "...): it is not the broker that made the token, or the broker's CA was made"
                + " anew");
      }
      try {
        KeyStore store = KeyStore.getInstance(KeyStore.getDefaultType());
        store.load(null, null);
        store.setCertificateEntry("ca", ca);
        TrustManagerFactory factory =
            TrustManagerFactory.getInstance(TrustManagerFactory.getDefaultAlgorithm());
        factory.init(store);
        for (TrustManager manager : factory.getTrustManagers()) {
          if (manager instanceof X509TrustManager x509) {
            x509.checkServerTrusted(chain, authType);
            return;
          }
        }
        throw new CertificateException("no X.509 trust manager in this JVM");
      } catch (java.io.IOException | GeneralSecurityException error) {
        if (error instanceof CertificateException certificate) {
          throw certificate;
        }
        throw new CertificateException(error);
      }
    }

    @Override
    public void checkClientTrusted(X509Certificate[] chain, String authType)
        throws CertificateException {
      throw new CertificateException("a sender does not accept client certificates");
    }

    @Override
    public X509Certificate[] getAcceptedIssuers() {
      return new X509Certificate[0];
    }
  }
}
