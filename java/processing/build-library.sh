#!/usr/bin/env sh
# Packs the Processing library feelmysign for Processing 4's Contribution Manager, after
# `mvn package` of java/ (make processing-library runs both):
#   java/processing/target/dist/feelmysign.zip   feelmysign/{library,examples,reference,src}
#                                                and feelmysign/library.properties
#   java/processing/target/dist/feelmysign.txt   library.properties, which the Contribution
#                                                Manager reads beside the zip
set -eu
here=$(cd "$(dirname "$0")" && pwd)
java_dir=$(cd "$here/.." && pwd)
target="$here/target"
stage="$target/stage/feelmysign"
dist="$target/dist"
for need in "$target/feelmysign.jar" "$target/compile-classpath.txt"; do
  if [ ! -f "$need" ]; then
    echo "Error: $need is not built yet; run 'make processing-library' in the repository." >&2
    exit 1
  fi
done
rm -rf "$target/stage" "$dist"
mkdir -p "$stage/library" "$stage/src" "$stage/reference" "$dist"

# library/: the library's jar (named as the library, as Processing requires) and the jars it
# needs. Processing's own core is not there: the PDE brings it.
cp "$target/feelmysign.jar" "$stage/library/feelmysign.jar"
cp "$target"/library-jars/*.jar "$stage/library/"

# src/: the sources of the library and of the two modules it is built on.
for module in core client processing; do
  cp -R "$java_dir/$module/src/main/java/." "$stage/src/"
done

cp -R "$here/examples" "$stage/examples"
cp "$here/library.properties" "$stage/library.properties"

# reference/: javadoc of the library's public API (index.html at its top).
javadoc -quiet -Xdoclint:none -encoding UTF-8 -notimestamp \
  -windowtitle "feelmysign for Processing" -doctitle "feelmysign for Processing" \
  -d "$stage/reference" -sourcepath "$stage/src" \
  -classpath "$(cat "$target/compile-classpath.txt")" \
  feelmysign.processing feelmysign.client feelmysign.protocol feelmysign.simplify feelmysign.shapes \
  >"$target/javadoc.log" 2>&1 || { cat "$target/javadoc.log" >&2; exit 1; }

# One folder, feelmysign/, in the zip: the Contribution Manager installs it as it is.
(cd "$target/stage" && find feelmysign -exec touch -d 2026-01-01T00:00:00Z {} + \
  && find feelmysign -type f | LC_ALL=C sort | zip -q -X -D "$dist/feelmysign.zip" -@)
cp "$here/library.properties" "$dist/feelmysign.txt"
echo "$dist/feelmysign.zip ($(unzip -Z1 "$dist/feelmysign.zip" | wc -l) files) and $dist/feelmysign.txt"
