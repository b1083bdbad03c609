package feelmysign.processing;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.io.InputStream;
import java.io.StringReader;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Properties;
import java.util.Set;
import java.util.jar.JarFile;
import java.util.zip.ZipEntry;
import java.util.zip.ZipFile;
import org.junit.jupiter.api.Test;

/**
 * feelmysign.zip as Processing 4's Contribution Manager wants it (the library template and
 * the "Library Basics" rules): one folder named as the library, library/&lt;name&gt;.jar,
 * examples/, reference/index.html, src/, library.properties with every field it reads, and
 * the same file as feelmysign.txt beside the zip.
 */
class LibraryZipIT {
  private static final Path DIST = Path.of("target/dist");
  private static final Set<String> CATEGORIES =
      Set.of("3D", "Animation", "Compilations", "Data", "Fabrication", "Geometry", "GUI",
          "Hardware", "I/O", "Language", "Math", "Simulation", "Sound", "Utilities",
          "Typography", "Video & Vision");

  @Test
  void theZipHasTheLayoutProcessingInstalls() throws IOException {
    List<String> names = new ArrayList<>();
    try (ZipFile zip = new ZipFile(DIST.resolve("feelmysign.zip").toFile())) {
      zip.stream().map(ZipEntry::getName).forEach(names::add);
      for (String name : names) {
        assertTrue(name.startsWith("feelmysign/"), name + " is outside the feelmysign/ folder");
      }
      for (String needed : List.of("feelmysign/library/feelmysign.jar",
          "feelmysign/library.properties", "feelmysign/reference/index.html",
          "feelmysign/examples/PaperSketch/PaperSketch.pde",
          "feelmysign/examples/ModernSketch/ModernSketch.pde",
          "feelmysign/examples/StudyShape/StudyShape.pde",
          "feelmysign/src/feelmysign/processing/FeelMySign.java",
          "feelmysign/library/hivemq-mqtt-client-1.3.7.jar",
          "feelmysign/library/feelmysign-core-0.1.0.jar")) {
        assertTrue(names.contains(needed), needed + " is missing from the zip");
      }
      // Processing's core comes with the PDE; a second copy in library/ would clash with it.
      assertFalse(names.stream().anyMatch(n -> n.matches("feelmysign/library/core-.*\\.jar")),
          "Processing's core.jar must not be in library/");
      // Every example sits in a folder of its own name, as the PDE opens it.
      for (String name : names) {
        if (name.endsWith(".pde")) {
          String[] parts = name.split("/");
          assertEquals(parts[2] + ".pde", parts[3], name + ": the sketch and its folder differ");
        }
      }
      // The library's jar holds the API a sketch imports, built for Processing 4's Java 17.
      Path jar = Files.createTempFile("feelmysign", ".jar");
      try (InputStream in = zip.getInputStream(zip.getEntry("feelmysign/library/feelmysign.jar"))) {
        Files.copy(in, jar, java.nio.file.StandardCopyOption.REPLACE_EXISTING);
      }
      try (JarFile library = new JarFile(jar.toFile())) {
        ZipEntry main = library.getEntry("feelmysign/processing/FeelMySign.class");
        assertTrue(main != null, "feelmysign.jar has no feelmysign.processing.FeelMySign");
        try (InputStream in = library.getInputStream(main)) {
          byte[] head = in.readNBytes(8);
          int major = ((head[6] & 0xff) << 8) | (head[7] & 0xff);
          assertEquals(61, major, "class file version (61 is Java 17, what Processing 4 runs)");
        }
      } finally {
        Files.delete(jar);
      }
      // The properties inside the zip and beside it are the same file.
      String inside;
      try (InputStream in = zip.getInputStream(zip.getEntry("feelmysign/library.properties"))) {
        inside = new String(in.readAllBytes(), java.nio.charset.StandardCharsets.UTF_8);
      }
      assertEquals(inside, Files.readString(DIST.resolve("feelmysign.txt")));
    }
  }

  @Test
  void libraryPropertiesHasEveryFieldTheContributionManagerReads() throws IOException {
    Properties p = new Properties();
    p.load(new StringReader(Files.readString(DIST.resolve("feelmysign.txt"))));
    for (String field : List.of("name", "version", "prettyVersion", "authors", "url",
        "categories", "sentence", "paragraph", "minRevision", "maxRevision")) {
      assertTrue(p.getProperty(field) != null, field + " is missing");
      // url stays empty until the project has a page of its own (see library.properties).
      assertTrue(!p.getProperty(field).isBlank() || field.equals("paragraph")
          || field.equals("url"), field + " is empty");
    }
    assertEquals("feelmysign", p.getProperty("name"));
    // version: an integer that counts releases; revisions: integers, 0 for "no limit".
    for (String integer : List.of("version", "minRevision", "maxRevision")) {
      Integer.parseInt(p.getProperty(integer).trim());
    }
    assertTrue(Integer.parseInt(p.getProperty("version").trim()) >= 1);
    assertEquals(FeelMySign.VERSION, p.getProperty("prettyVersion").trim());
    for (String category : p.getProperty("categories").split(",")) {
      assertTrue(CATEGORIES.contains(category.trim()), category + " is not a category of the list");
    }
    String url = p.getProperty("url").trim();
    assertTrue(url.isEmpty() || url.startsWith("https://"), "url: a web page, or none yet");
    String sentence = p.getProperty("sentence").trim();
    assertTrue(Character.isUpperCase(sentence.charAt(0)) && sentence.endsWith("."),
        "sentence: capitalised, ending with a period");
  }
}
