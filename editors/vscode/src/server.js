// How the extension starts the language server: `<inspc.path> lsp` over stdio. Kept apart
// from extension.js (which needs VS Code) so the tests can start the same command.
"use strict";

/** The executable and arguments of the server for the extension's settings. */
function serverCommand(settings) {
  const path = (settings && settings.path) || "inspc";
  return { command: path, args: ["lsp"] };
}

/** The documents the client sends to the server. */
const documentSelector = [
  { scheme: "file", language: "insp" },
  { scheme: "untitled", language: "insp" },
];

module.exports = { serverCommand, documentSelector };
