package feelmysign;

import java.lang.annotation.ElementType;
import java.lang.annotation.Retention;
import java.lang.annotation.RetentionPolicy;
import java.lang.annotation.Target;
import java.util.stream.Stream;
import org.junit.jupiter.api.extension.ExtensionContext;
import org.junit.jupiter.params.provider.AnnotationBasedArgumentsProvider;
import org.junit.jupiter.params.provider.Arguments;
import org.junit.jupiter.params.provider.ArgumentsSource;
import org.junit.jupiter.params.support.ParameterDeclarations;

/**
 * A parameterized test's cases: every vector under testdata/{@code value} (see {@link
 * Vectors#cases}), as (name, tree).
 *
 * <pre>
 * &#64;ParameterizedTest(name = "{0}")
 * &#64;VectorFiles("control/valid")
 * void reads(String name, JsonNode vector) { ... }
 * </pre>
 */
@Target(ElementType.METHOD)
@Retention(RetentionPolicy.RUNTIME)
@ArgumentsSource(VectorFiles.Provider.class)
public @interface VectorFiles {
  /** The folder under testdata/, e.g. "angle" or "protocol/valid". */
  String value();

  /** Reads the folder the annotation names. */
  final class Provider extends AnnotationBasedArgumentsProvider<VectorFiles> {
    @Override
    protected Stream<? extends Arguments> provideArguments(
        ParameterDeclarations parameters, ExtensionContext context, VectorFiles files) {
      return Vectors.cases(files.value());
    }
  }
}
