#!/usr/bin/env bash
# Seeds the fuzz corpora from the repository's own inputs (run from fuzz/).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p corpus/spec corpus/check corpus/mesh corpus/dmis corpus/lsp
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
