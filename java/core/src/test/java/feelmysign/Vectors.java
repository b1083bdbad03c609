package feelmysign;

import com.fasterxml.jackson.databind.DeserializationFeature;
import com.fasterxml.jackson.databind.JsonNode;
import com.fasterxml.jackson.databind.ObjectMapper;
import java.io.IOException;
import java.io.UncheckedIOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.stream.Stream;
import org.junit.jupiter.params.provider.Arguments;

/**
 * The shared vectors in the repository's testdata/ (written by the Python reference), read with
 * Jackson: a parser of the tests' own, not the port's.
 */
public final class Vectors {
  private Vectors() {}

  public static final ObjectMapper MAPPER =
      new ObjectMapper().enable(DeserializationFeature.USE_BIG_INTEGER_FOR_INTS);

  /** testdata/, found upwards from the working directory (a module's folder under java/). */
  public static Path testdata() {
    Path here = Path.of("").toAbsolutePath();
    for (Path dir = here; dir != null; dir = dir.getParent()) {
      Path candidate = dir.resolve("testdata");
      if (Files.isDirectory(candidate.resolve("protocol"))) {
        return candidate;
      }
    }
    throw new IllegalStateException("no testdata/ above " + here);
  }

  /** Every .json file under testdata/part (sorted), as (name, tree), params.json left out. */
  public static Stream<Arguments> cases(String part) {
    Path root = testdata().resolve(part);
    List<Arguments> out = new ArrayList<>();
    try (Stream<Path> files = Files.walk(root)) {
      for (Path file : files.filter(p -> p.toString().endsWith(".json")).sorted().toList()) {
        if (file.getFileName().toString().equals("params.json")) {
          continue;
        }
        out.add(Arguments.of(root.relativize(file).toString(), read(file)));
      }
    } catch (IOException error) {
      throw new UncheckedIOException(error);
    }
    if (out.isEmpty()) {
      throw new IllegalStateException("no vectors under " + root);
    }
    return out.stream();
  }

  public static JsonNode read(Path file) {
    try {
      return MAPPER.readTree(file.toFile());
    } catch (IOException error) {
      throw new UncheckedIOException(error);
    }
  }

  /** A JSON value as the port's values: Map, List, String, Long/BigInteger, Double, Boolean. */
  public static Object plain(JsonNode node) {
    if (node == null || node.isNull() || node.isMissingNode()) {
      return null;
    }
    if (node.isIntegralNumber()) {
      java.math.BigInteger big = node.bigIntegerValue();
      return big.bitLength() < 64 ? (Object) big.longValue() : big;
    }
    if (node.isNumber()) {
      return node.doubleValue();
    }
    if (node.isBoolean()) {
      return node.booleanValue();
    }
    if (node.isTextual()) {
      return node.textValue();
    }
    if (node.isArray()) {
      List<Object> list = new ArrayList<>();
      node.forEach(item -> list.add(plain(item)));
      return list;
    }
    Map<String, Object> map = new java.util.LinkedHashMap<>();
    node.properties().forEach(e -> map.put(e.getKey(), plain(e.getValue())));
    return map;
  }
}
