#!/usr/bin/env bash
# Seeds the fuzz corpora from the repository's own inputs (run from fuzz/).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p corpus/spec corpus/check corpus/mesh corpus/dmis corpus/simulate corpus/step corpus/qif corpus/lsp
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
# Language server sessions: initialize, open a spec, ask at a few places, shut down,
# each message framed as the base protocol frames it.
if command -v python3 >/dev/null; then
    python3 - ../examples/*.insp <<'PY'
import json, sys, os
for path in sys.argv[1:]:
    text = open(path, encoding="utf-8").read()
    uri = "file:///fuzz/" + os.path.basename(path)
    doc = {"textDocument": {"uri": uri}}
    msgs = [
        {"id": 1, "method": "initialize", "params": {"capabilities": {}}},
        {"method": "initialized", "params": {}},
        {"method": "textDocument/didOpen", "params": {"textDocument": {
            "uri": uri, "languageId": "insp", "version": 1, "text": text}}},
    ]
    for i, (line, ch) in enumerate([(2, 10), (5, 14), (8, 4), (12, 20)]):
        at = dict(doc, position={"line": line, "character": ch})
        msgs.append({"id": 10 + i, "method": "textDocument/hover", "params": at})
        msgs.append({"id": 20 + i, "method": "textDocument/completion", "params": at})
        msgs.append({"id": 30 + i, "method": "textDocument/definition", "params": at})
        msgs.append({"id": 40 + i, "method": "textDocument/rename",
                     "params": dict(at, newName="renamed")})
    msgs.append({"id": 50, "method": "textDocument/documentSymbol", "params": doc})
    msgs.append({"id": 51, "method": "textDocument/formatting",
                 "params": dict(doc, options={"tabSize": 4, "insertSpaces": True})})
    msgs.append({"id": 52, "method": "shutdown"})
    msgs.append({"method": "exit"})
    out = b""
    for m in msgs:
        body = json.dumps(dict(m, jsonrpc="2.0")).encode()
        out += b"Content-Length: %d\r\n\r\n" % len(body) + body
    name = "corpus/lsp/" + path.replace("/", "_").replace(".", "_")
    open(name, "wb").write(out)
PY
fi
