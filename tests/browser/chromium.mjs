// What the editor's browser tests share: Debian's headless chromium (WebGL through SwiftShader)
// driven by playwright-core from tools/editor/web/node_modules, one 1280x720 page, and the problems
// it reports (page errors, console errors, responses of 400 and above) collected for the test to
// fail on.
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, '../../tools/editor/web/package.json'));
const { chromium } = require('playwright-core');

/** { browser, page, problems }: close the browser when done. */
export async function openPage() {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--font-render-hinting=none'],
  });
  const page = await browser.newPage({ viewport: { width: 1280, height: 720 }, deviceScaleFactor: 1 });
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
  page.on('response', (r) => { if (r.status() >= 400) problems.push(`${r.status()}: ${r.url()}`); });
  return { browser, page, problems };
}
