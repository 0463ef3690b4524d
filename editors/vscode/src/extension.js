// The VS Code side of inspc: starts `inspc lsp` as the language client's server. Every
// feature (diagnostics, hover, definition, references, symbols, completion, rename,
// formatting) is the server's; format on save is a configuration default
// (package.json).
"use strict";
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");
const { serverCommand, documentSelector } = require("./server");

let client;

async function activate(context) {
  const settings = vscode.workspace.getConfiguration("inspc");
  const { command, args } = serverCommand({ path: settings.get("path") });
  const run = { command, args, transport: TransportKind.stdio };
  client = new LanguageClient(
    "inspc",
    "inspc",
    { run, debug: run },
    { documentSelector, outputChannelName: "inspc" },
  );
  context.subscriptions.push(
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration("inspc.path")) {
        vscode.window.showInformationMessage("inspc: reload the window to use the new server path.");
      }
    }),
  );
  await client.start();
}

async function deactivate() {
  if (client) {
    await client.stop();
  }
}

module.exports = { activate, deactivate };
