// The TextMate grammar: in step with grammar/insp.pest, and tokenizing real specs as an
// editor would (vscode-textmate with the Oniguruma engine VS Code uses).
import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";
import { join, dirname } from "node:path";
import { fileURLToPath } from "node:url";
import { generated, grammarPath, keywords, pestPath } from "../scripts/grammar.mjs";

const require = createRequire(import.meta.url);
const here = dirname(fileURLToPath(import.meta.url));
const repo = join(here, "../../..");

test("the checked-in grammar is what grammar/insp.pest generates", () => {
  assert.equal(readFileSync(grammarPath, "utf8"), generated(), "run `npm run grammar`");
  const { declaring, other } = keywords(readFileSync(pestPath, "utf8"));
  const rules = readFileSync(pestPath, "utf8").match(/^kw_\w+/gm).length;
  // Every kw_ rule has one word; block_kw has the nine catalogue items.
  assert.equal(declaring.length + other.length, rules + 9);
});

async function grammar() {
  const oniguruma = require("vscode-oniguruma");
  const textmate = require("vscode-textmate");
  const wasm = readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm")).buffer;
  await oniguruma.loadWASM(wasm);
  const registry = new textmate.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (p) => new oniguruma.OnigScanner(p),
      createOnigString: (s) => new oniguruma.OnigString(s),
    }),
    loadGrammar: async () => textmate.parseRawGrammar(readFileSync(grammarPath, "utf8"), grammarPath),
  });
  return { g: await registry.loadGrammar("source.insp"), INITIAL: textmate.INITIAL };
}

/** Each token of `text` as [text, innermost scope], line by line. */
function tokens(g, INITIAL, text) {
  let stack = INITIAL;
  const out = [];
  for (const line of text.split("\n")) {
    const r = g.tokenizeLine(line, stack);
    for (const t of r.tokens) {
      out.push([line.slice(t.startIndex, t.endIndex), t.scopes[t.scopes.length - 1]]);
    }
    stack = r.ruleStack;
  }
  return out;
}

function scopeOf(toks, text) {
  const t = toks.find(([s]) => s === text);
  assert.ok(t, `no token ${JSON.stringify(text)}`);
  return t[1];
}

test("a real spec's tokens", async () => {
  const { g, INITIAL } = await grammar();
  const f2 = tokens(g, INITIAL, readFileSync(join(repo, "examples/f2.insp"), "utf8"));
  assert.equal(scopeOf(f2, "part"), "keyword.declaration.insp");
  assert.equal(scopeOf(f2, "f2"), "entity.name.type.insp");
  assert.equal(scopeOf(f2, "use"), "keyword.declaration.insp");
  assert.equal(scopeOf(f2, "large_slot"), "variable.other.constant.insp");
  assert.equal(scopeOf(f2, "0.05"), "constant.numeric.insp");
  assert.equal(scopeOf(f2, "mm"), "keyword.other.unit.insp");
  assert.equal(scopeOf(f2, "+y"), "constant.language.direction.insp");
  assert.equal(scopeOf(f2, "perpendicularity"), "entity.name.function.insp");
  assert.match(f2[0][1], /^comment\.line/);
  const ctc = tokens(g, INITIAL, readFileSync(join(repo, "tests/real/nist_ctc_01.insp"), "utf8"));
  assert.equal(scopeOf(ctc, '"'), "string.quoted.double.insp");
  assert.equal(scopeOf(ctc, "group"), "keyword.other.insp");
  assert.equal(scopeOf(ctc, "±"), "keyword.operator.insp");
  assert.equal(scopeOf(ctc, "deg"), "keyword.other.unit.insp");
  // A stylus name's digits are part of the name, not a number.
  const probe = tokens(g, INITIAL, "    probes [p1: TP20_D4_L50]");
  assert.ok(!probe.some(([, scope]) => scope === "constant.numeric.insp"), JSON.stringify(probe));
});
