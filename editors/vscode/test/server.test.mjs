// The command the extension starts (src/server.js), driven with the JSON-RPC library the
// extension's client uses: it must answer initialize, publish diagnostics, hover, and
// exit cleanly. INSPC names the inspc binary (the Rust test suite sets it).
import { test } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import { readFileSync, realpathSync } from "node:fs";
import { createRequire } from "node:module";
import { join, dirname } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const require = createRequire(import.meta.url);
const rpc = require("vscode-jsonrpc/node");
const { serverCommand, documentSelector } = require("../src/server.js");
const here = dirname(fileURLToPath(import.meta.url));

test("the extension's server command serves a spec", { skip: !process.env.INSPC && "INSPC is not set" }, async () => {
  const { command, args } = serverCommand({ path: process.env.INSPC });
  assert.deepEqual(args, ["lsp"]);
  assert.ok(documentSelector.some((s) => s.language === "insp"));
  const child = spawn(command, args, { stdio: ["pipe", "pipe", "inherit"] });
  const conn = rpc.createMessageConnection(
    new rpc.StreamMessageReader(child.stdout),
    new rpc.StreamMessageWriter(child.stdin),
  );
  const published = new Promise((resolve) =>
    conn.onNotification("textDocument/publishDiagnostics", resolve),
  );
  conn.listen();
  const init = await conn.sendRequest("initialize", { processId: process.pid, rootUri: null, capabilities: {} });
  assert.equal(init.capabilities.hoverProvider, true);
  assert.equal(init.capabilities.documentFormattingProvider, true);
  conn.sendNotification("initialized", {});
  const path = realpathSync(join(here, "../../../examples/f2.insp"));
  const uri = pathToFileURL(path).href;
  const text = readFileSync(path, "utf8");
  conn.sendNotification("textDocument/didOpen", {
    textDocument: { uri, languageId: "insp", version: 1, text },
  });
  const diags = await published;
  assert.equal(diags.uri, uri);
  assert.deepEqual(diags.diagnostics, []);
  const line = text.split("\n").findIndex((l) => l.includes("head PH6"));
  const hover = await conn.sendRequest("textDocument/hover", {
    textDocument: { uri },
    position: { line, character: text.split("\n")[line].indexOf("PH6") + 1 },
  });
  assert.match(hover.contents.value, /head PH6: fixed/);
  await conn.sendRequest("shutdown");
  const exited = new Promise((resolve) => child.on("exit", resolve));
  conn.sendNotification("exit");
  assert.equal(await exited, 0);
  conn.dispose();
});
