// The editor's page in Debian's headless chromium (WebGL through SwiftShader), driven by
// playwright-core from tools/editor/web/node_modules: open the URL `volmorph edit` printed, take a
// screenshot of the loaded page, select pair 2, drag its target origin with the gizmo, save.
// Prints one JSON line: {"dragToMeshMs", "morphUpdates", ...}. Exit 0 when every step passed.
// usage: node editor_test.mjs URL OUT_DIR [DRAGS]
import path from 'node:path';

import { openPage } from './chromium.mjs';

const [url, out, dragCount = '1'] = process.argv.slice(2);
const fail = (message) => { console.error(`editor_test: ${message}`); process.exit(1); };
if (!url || !out) fail('usage: node editor_test.mjs URL OUT_DIR [DRAGS]');

const pairCount = (page) => page.evaluate(() => window.volmorphEditor.state().pairs.length);

/** Waits for the state to satisfy `test` (a function of the state, or its source), polled here: a
 * predicate given as text would be evaluated in the page, which its Content-Security-Policy forbids. */
async function stateWhere(page, test, what) {
  const check = typeof test === 'string' ? new Function('s', `return (${test})(s);`) : test;
  const deadline = Date.now() + 30000;
  let state;
  while (Date.now() < deadline) {
    state = await page.evaluate(() => window.volmorphEditor.state());
    if (check(state)) return;
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  fail(`${what}: ${JSON.stringify(state)}`);
}

/** After the save (the file is checked as saved): the validator's error shown at its element and
 * undone, add, duplicate, delete with undo and redo, suggest, snapping to the surface, the slider. */
async function otherEdits(page) {
  await page.fill('input[data-key="target.scale.0"]', '0');
  await page.press('input[data-key="target.scale.0"]', 'Enter');
  await stateWhere(page, (s) => !s.valid && s.errors[0].pair === 2 && s.errors[0].side === 'target', 'no error at pair 2');
  await page.waitForSelector('#labels .label.error', { timeout: 10000 });
  const listed = await page.textContent('#errors');
  if (!listed.includes('scale')) fail(`the problems list says: ${listed}`);
  await page.click('#undo');
  await stateWhere(page, (s) => s.valid, 'undo did not clear the error');
  await page.waitForSelector('#labels .label.error', { state: 'detached', timeout: 10000 });

  const n = await pairCount(page);
  await page.selectOption('#new-type', 'box');
  await page.click('#add');
  await stateWhere(page, `(s) => s.pairs.length === ${n + 1} && s.pairs[${n}].type === 'box'`, 'add');
  await page.click('#duplicate');
  await stateWhere(page, `(s) => s.pairs.length === ${n + 2}`, 'duplicate');
  await page.click('#delete');
  await stateWhere(page, `(s) => s.pairs.length === ${n + 1}`, 'delete');
  await page.mouse.click(5, 300); // the keys go to the page, not a field
  await page.keyboard.press('Control+z');
  await stateWhere(page, `(s) => s.pairs.length === ${n + 2}`, 'Ctrl+Z');
  await page.keyboard.press('Control+Shift+z');
  await stateWhere(page, `(s) => s.pairs.length === ${n + 1}`, 'Ctrl+Shift+Z');
  await page.click('#suggest');
  await stateWhere(page, `(s) => s.pairs.length > ${n + 1}`, 'suggest');

  // Shift+click on the target's surface: pair 2's target origin moves onto it.
  await page.click('#pair-list li[data-pair="2"]');
  await page.check('input[name=side][value=target]');
  const at = await page.evaluate(() => window.volmorphEditor.surfacePixel('target'));
  if (!at) fail('no pixel shows the target');
  await page.keyboard.down('Shift');
  await page.mouse.click(at.x, at.y);
  await page.keyboard.up('Shift');
  const snapped = at.point.map((v) => Math.round(v * 1e4) / 1e4);
  await stateWhere(page, `(s) => s.pairs[1].target.origin.every((v, i) => Math.abs(v - ${JSON.stringify(snapped)}[i]) < 1e-6)`, 'snap');

  const updates = await page.evaluate(() => window.volmorphEditor.morphUpdates);
  await page.fill('#t', '0.2');
  await page.dispatchEvent('#t', 'change');
  await page.waitForFunction((u) => window.volmorphEditor.morphUpdates > u, updates, { timeout: 30000 });
}

const { browser, page, problems } = await openPage();
try {
  await page.goto(url);
  // The printed URL's token went into the session's cookie: the page's own URL carries none.
  if (new URL(page.url()).search !== '') fail(`the page's URL still carries the token: ${page.url()}`);
  await page.waitForFunction(() => window.volmorphEditor && window.volmorphEditor.ready, null, { timeout: 120000 });
  const webgl = await page.evaluate(() => {
    const gl = document.querySelector('#view canvas').getContext('webgl2');
    return gl ? gl.getParameter(gl.VERSION) : null;
  });
  if (!webgl) fail('no WebGL 2 context');
  await page.mouse.move(0, 0);
  await page.screenshot({ path: path.join(out, 'editor.png') });
  const renderMs = await page.evaluate(() => window.volmorphEditor.renderMs(5));

  // Select pair 2, its target side, and move the gizmo's centre handle.
  await page.click('#pair-list li[data-pair="2"]');
  await page.check('input[name=side][value=target]');
  const before = await page.evaluate(() => window.volmorphEditor.state().pairs[1].target.origin);
  const timings = [], parts = [];
  for (let i = 0; i < Number(dragCount); ++i) {
    const updates = await page.evaluate(() => window.volmorphEditor.morphUpdates);
    const at = await page.evaluate(() => window.volmorphEditor.screenPosition(2, 'target'));
    const dx = i % 2 ? -40 : 40;
    await page.mouse.move(at.x, at.y);
    await page.mouse.down();
    for (let k = 1; k <= 8; ++k) await page.mouse.move(at.x + (dx * k) / 8, at.y + (12 * k) / 8);
    await page.mouse.up();
    await page.waitForFunction((n) => window.volmorphEditor.morphUpdates > n, updates, { timeout: 30000 });
    timings.push(await page.evaluate(() => window.volmorphEditor.lastUpdateMs));
    parts.push(await page.evaluate(() => window.volmorphEditor.timing));
  }
  const after = await page.evaluate(() => window.volmorphEditor.state().pairs[1].target.origin);
  if (JSON.stringify(before) === JSON.stringify(after)) fail(`the drag did not move the origin (${after})`);

  await page.click('#save');
  await page.waitForFunction(() => !window.volmorphEditor.state().dirty, null, { timeout: 30000 });
  await page.screenshot({ path: path.join(out, 'edited.png') });
  await otherEdits(page);
  if (problems.length) fail(problems.join('\n'));
  const sorted = [...timings].sort((a, b) => a - b);
  console.log(JSON.stringify({ webgl, renderMs, before, after, dragToMeshMs: timings, parts,
                               medianMs: sorted[Math.floor(sorted.length / 2)] }));
} finally {
  await browser.close();
}
