// The editor's page on a scene with a [timing] sweep (issue 59) in headless chromium: the
// in-between arrives with each vertex's delay and is coloured by it (the delays span most of the
// spread: the sweep runs floor up across the shapes); the sweep's end handle, clicked, then dragged
// sideways with the gizmo, turns the sweep: the state's direction changes and the in-between is made
// again with other delays; then the scene is saved (editor.sh checks that the sweep's line alone
// changed). Leaves editor-timing.png in OUT_DIR.
// usage: node editor_timing.mjs URL OUT_DIR
import path from 'node:path';

import { openPage } from './chromium.mjs';

const [url, out] = process.argv.slice(2);
const fail = (message) => { console.error(`editor_timing: ${message}`); process.exit(1); };
if (!url || !out) fail('usage: node editor_timing.mjs URL OUT_DIR');

const hook = (page, name, ...args) =>
  page.evaluate(([n, a]) => window.volmorphEditor[n](...a), [name, args]);

async function until(page, test, what, timeoutMs = 60000) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const value = await test();
    if (value) return value;
    if (Date.now() > deadline) fail(`${what} (status: ${await page.textContent('#status')})`);
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
}

const { browser, page, problems } = await openPage();
try {
  await page.goto(url);
  await page.waitForFunction(() => window.volmorphEditor && window.volmorphEditor.ready, null, { timeout: 120000 });
  const state = await hook(page, 'state');
  const sweep = state.timing && state.timing.sweep;
  if (!sweep || !(state.timing.spread > 0)) fail(`no sweep in the state: ${JSON.stringify(state.timing)}`);
  if (await page.isHidden('#delay-legend')) fail('the delay legend is hidden');
  const delays = await hook(page, 'morphDelays');
  if (!delays.colored || delays.count < 100) fail(`the in-between is not coloured by its delays: ${JSON.stringify(delays)}`);
  if (!(delays.min >= 0 && delays.max <= state.timing.spread + 1e-6 && delays.max - delays.min > 0.5 * state.timing.spread))
    fail(`the delays do not span the spread ${state.timing.spread}: ${JSON.stringify(delays)}`);
  await page.mouse.move(0, 0);
  await page.screenshot({ path: path.join(out, 'editor-timing.png') });

  // Click the end handle, then drag the gizmo's centre sideways: the sweep turns.
  const end = await hook(page, 'sweepScreenPosition', 'end');
  if (!end || !end.visible) fail(`the sweep's end handle is not on the page: ${JSON.stringify(end)}`);
  await page.mouse.click(end.x, end.y);
  if ((await hook(page, 'sweepHandle')) !== 'end') fail('a click on the end handle did not select it');
  const updates = await page.evaluate(() => window.volmorphEditor.morphUpdates);
  await page.mouse.move(end.x, end.y);
  await page.mouse.down();
  for (let k = 1; k <= 8; ++k) await page.mouse.move(end.x + 5 * k, end.y);
  await page.mouse.up();
  const turned = await until(page, async () => {
    const s = await hook(page, 'state');
    return JSON.stringify(s.timing.sweep.direction) !== JSON.stringify(sweep.direction) && s.timing.sweep;
  }, 'the drag did not turn the sweep');
  await until(page, async () => (await page.evaluate(() => window.volmorphEditor.morphUpdates)) > updates,
    'no new in-between after the sweep turned');
  const length = Math.hypot(...turned.direction);
  if (Math.abs(length - 1) > 1e-3) fail(`the new direction is not a unit vector: ${turned.direction}`);
  if (JSON.stringify(turned.origin) !== JSON.stringify(sweep.origin)) fail('the end handle moved the origin');

  await page.click('#save');
  await page.waitForFunction(() => !window.volmorphEditor.state().dirty, null, { timeout: 30000 });
  if (problems.length) fail(problems.join('\n'));
  console.log(JSON.stringify({ delays, before: sweep, after: turned }));
} finally {
  await browser.close();
}
