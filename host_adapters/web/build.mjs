// Bundles the page into dist/ (index.html, app.js, app.css): three.js, uPlot and the shared colour
// function (host_adapters/node/lib/colors.js) are bundled in, so the page loads with no network and
// also opens as a file (a classic script, not a module: file:// pages cannot load modules).
//   node build.mjs            one build
//   node build.mjs --watch    rebuild on change
import * as esbuild from 'esbuild';
import { copyFile, mkdir, rm } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const src = path.join(here, 'src');
const dist = path.join(here, 'dist');
const watch = process.argv.includes('--watch');

const options = {
  entryPoints: { app: path.join(src, 'main.js') },
  outdir: dist,
  bundle: true,
  format: 'iife',
  platform: 'browser',
  target: ['es2020', 'chrome100', 'firefox100', 'safari15'],
  minify: !watch,
  sourcemap: watch ? 'inline' : false,
  legalComments: 'none',
  logLevel: 'warning',
  plugins: [{
    name: 'copy-html',
    setup(build) {
      build.onEnd(async (result) => {
        if (result.errors.length === 0) await copyFile(path.join(src, 'index.html'), path.join(dist, 'index.html'));
      });
    },
  }],
};

await rm(dist, { recursive: true, force: true });
await mkdir(dist, { recursive: true });
if (watch) {
  const ctx = await esbuild.context(options);
  await ctx.watch();
  console.log(`watching ${src} -> ${dist}`);
} else {
  await esbuild.build(options);
  console.log(`built ${path.relative(process.cwd(), dist) || '.'}: index.html, app.js, app.css`);
}
