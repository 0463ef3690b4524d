#!/usr/bin/env bash
# Seeds the fuzz corpora from the repository's own inputs (run from fuzz/).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p corpus/spec corpus/check corpus/mesh corpus/dmis corpus/step corpus/qif
for f in ../examples/*.insp ../examples/parts/*.insp ../tests/cases/*/main.insp ../stdlib/*.insp; do
    n=$(echo "$f" | tr '/.' '__')
    cp "$f" "corpus/spec/$n"
    cp "$f" "corpus/check/$n"
done
# Meshes: a leading byte picks the reader (even: STL, odd: OBJ).
for f in ../tests/cases/*/*.stl; do
    n=$(echo "$f" | tr '/.' '__')
    { printf '\x00'; cat "$f"; } > "corpus/mesh/$n"
done
if [ -d ../../shared/parts ]; then
    for f in ../../shared/parts/*.obj; do
        n=$(basename "$f")
        # The NIST meshes are large; the first 64 KiB seed the OBJ grammar.
        { printf '\x01'; head -c 65536 "$f"; } > "corpus/mesh/$n"
    done
fi
for f in ../tests/cases/*/program.dmi; do
    n=$(echo "$f" | tr '/.' '__')
    cp "$f" "corpus/dmis/$n"
done
# CAD parts: the suite's STEP and QIF files and the NIST parts beside the repository.
for f in $(find ../tests ../examples -name '*.stp' -o -name '*.step') \
    $(ls ../../shared/parts/*.stp ../../shared/parts/*/*.stp ../../shared/parts/*/*.step 2>/dev/null); do
    cp "$f" "corpus/step/$(echo "$f" | tr '/.' '__')"
done
for f in $(find ../tests ../examples -name '*.qif') $(ls ../../shared/parts/*.qif 2>/dev/null); do
    cp "$f" "corpus/qif/$(echo "$f" | tr '/.' '__')"
done
