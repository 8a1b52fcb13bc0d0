// Bundles the viewer's front end into one classic script (no ES modules: a page opened from disk
// may not import them) and copies the page beside it. Run by the CMake build:
//   node app/view/web/build.mjs OUTDIR
// Everything comes from node_modules (npm ci); nothing is fetched.
import { build } from 'esbuild';
import { copyFileSync, mkdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const out = process.argv[2];
if (!out) {
  console.error('usage: node build.mjs OUTDIR');
  process.exit(2);
}
mkdirSync(out, { recursive: true });
await build({
  entryPoints: [join(here, 'src', 'main.js')],
  bundle: true,
  format: 'iife',
  minify: true,
  target: 'es2020',
  outfile: join(out, 'viewer.js'),
  legalComments: 'eof',
  logLevel: 'warning',
});
for (const f of ['index.html', 'viewer.css']) copyFileSync(join(here, f), join(out, f));
