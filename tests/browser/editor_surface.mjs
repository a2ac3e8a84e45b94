// The editor's page on a surface-mode scene (issue 57) in headless chromium: the pairs are
// landmarks (state.landmarks), so "Suggest pairs" and the new pair's type are disabled and the
// selected pair's type offers "point" alone; pair 1's target typed a little along its spike moves
// the landmark, and the in-between is made again (a new correspondence) with no request refused.
// Leaves a screenshot, editor-surface.png, in OUT_DIR.
// usage: node editor_surface.mjs URL OUT_DIR
import path from 'node:path';

import { openPage } from './chromium.mjs';

const [url, out] = process.argv.slice(2);
const fail = (message) => { console.error(`editor_surface: ${message}`); process.exit(1); };
if (!url || !out) fail('usage: node editor_surface.mjs URL OUT_DIR');

const { browser, page, problems } = await openPage();
try {
  await page.goto(url);
  await page.waitForFunction(() => window.volmorphEditor && window.volmorphEditor.ready, null, { timeout: 120000 });
  const state = await page.evaluate(() => window.volmorphEditor.state());
  if (!state.landmarks) fail('state.landmarks is not set for a surface-mode scene');
  if (!(await page.isDisabled('#suggest'))) fail('Suggest pairs is enabled in surface mode');
  if (!(await page.isDisabled('#new-type'))) fail('the new pair type can be chosen in surface mode');
  await page.click('#pair-list li[data-pair="1"]');
  const types = await page.$$eval('#fields select option', (o) => o.map((x) => x.value));
  if (JSON.stringify(types) !== '["point"]') fail(`the type selector offers ${types}`);

  // Pair 1's target (the star's -x spike, at x = -0.5) typed a little along the spike.
  const updates = await page.evaluate(() => window.volmorphEditor.morphUpdates);
  await page.fill('input[data-key="target.origin.0"]', '-0.45');
  await page.press('input[data-key="target.origin.0"]', 'Enter');
  const deadline = Date.now() + 60000;
  for (;;) {
    const s = await page.evaluate(() => window.volmorphEditor.state());
    if (s.pairs[0].target.origin[0] === -0.45) break;
    if (Date.now() > deadline) fail(`the landmark did not move: ${JSON.stringify(s.pairs[0])}`);
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  while ((await page.evaluate(() => window.volmorphEditor.morphUpdates)) <= updates) {
    if (problems.length || Date.now() > deadline) fail(`no new in-between: ${problems.join('\n')} ${await page.textContent('#status')}`);
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  await page.mouse.move(0, 0);
  await page.screenshot({ path: path.join(out, 'editor-surface.png') });
  if (problems.length) fail(problems.join('\n'));
  console.log(JSON.stringify({ morphUpdates: await page.evaluate(() => window.volmorphEditor.morphUpdates) }));
} finally {
  await browser.close();
}
