// web.build (ctest fixture web_dist): `npm run build` in host_adapters/web, after checking that
// the page's npm packages are installed.   node build-page.mjs [NPM]   (run in host_adapters/web)
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

const web = process.cwd();
for (const pkg of ['esbuild', 'three', 'uplot', 'playwright-core']) {
  if (!fs.existsSync(path.join(web, 'node_modules', pkg, 'package.json'))) {
    console.error(`web.build: ${path.join(web, 'node_modules')} has no ${pkg}: the page's packages are not installed.\n` +
      `  Install them with: (cd ${web} && npm ci)   (scripts/deps.sh does)`);
    process.exit(1);
  }
}
const build = spawnSync(process.argv[2] || 'npm', ['run', 'build'], { stdio: 'inherit' });
process.exit(build.status === null ? 1 : build.status);
