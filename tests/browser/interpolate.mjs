// The page's feature interpolation (tools/editor/web/page/features.js) run by Node on pairs given as
// JSON, for tests/unit/editor/page_interpolation_test.cpp, which holds it to Feature.cpp's.
// usage: node interpolate.mjs IN.json   IN: {"t": [...], "pairs": [{"source": {...}, "target": {...}}]}
// stdout: [[element at t[0], element at t[1], ...] for each pair], each {origin, axes, scale}
import fs from 'node:fs';
import { interpolate } from '../../tools/editor/web/page/features.js';

const input = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
const out = input.pairs.map((pair) => input.t.map((t) => interpolate(pair.source, pair.target, t)));
process.stdout.write(JSON.stringify(out));
