#!/usr/bin/env bash
# Seeds the fuzz corpora from the repository's own inputs (run from fuzz/).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p corpus/spec corpus/check corpus/mesh corpus/dmis corpus/simulate corpus/step corpus/qif
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
# The virtual CMM: F2's program, then a deviations file after 64 blank lines; the first
# byte (the share of 255 the program takes of the rest, rounded up) splits within them.
prog=../tests/cases/example_f2/program.dmi
for dev in "" "feature large_slot move (0.3, 0, 0)" "face stock.top bow 0.05" "part move (1, 0)
part turn 2" "setup 1 move (0.5, 0)"; do
    n=$(printf '%s' "$dev" | cksum | cut -d' ' -f1)
    size=$(wc -c < "$prog")
    total=$(( size + 64 + ${#dev} ))
    split=$(( (size * 255 + total - 1) / total ))
    { printf "\\$(printf '%03o' "$split")"; cat "$prog"; for _ in $(seq 64); do echo; done; printf '\n%s\n' "$dev"; } > "corpus/simulate/f2_$n"
done
# CAD parts: the suite's STEP and QIF files and the NIST parts beside the repository.
for f in $(find ../tests ../examples -name '*.stp' -o -name '*.step') \
    $(ls ../../shared/parts/*.stp ../../shared/parts/*/*.stp ../../shared/parts/*/*.step 2>/dev/null); do
    cp "$f" "corpus/step/$(echo "$f" | tr '/.' '__')"
done
for f in $(find ../tests ../examples -name '*.qif') $(ls ../../shared/parts/*.qif 2>/dev/null); do
    cp "$f" "corpus/qif/$(echo "$f" | tr '/.' '__')"
done
