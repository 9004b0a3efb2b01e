// Debian's Chromium, headless, driven by playwright-core: the one launch that the page's tests, the
// frame-rate measurement and the screenshot script share. Chromium comes from the system
// (/usr/bin/chromium, or $EMBRA_CHROMIUM), never downloaded; WebGL runs on SwiftShader (no GPU), and
// the background-networking flags keep it from calling out of this machine's closed network.

import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const require = createRequire(import.meta.url);
const here = path.dirname(fileURLToPath(import.meta.url));

export const chromiumPath = process.env.EMBRA_CHROMIUM || '/usr/bin/chromium';

/** A persistent headless context with a fresh profile in `profileDir` (a new empty folder). */
export function launchChromium(profileDir, viewport = { width: 1440, height: 900 }) {
  const { chromium } = require(path.join(here, 'node_modules', 'playwright-core'));
  return chromium.launchPersistentContext(profileDir, {
    executablePath: chromiumPath,
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
    viewport,
    deviceScaleFactor: 1,
  });
}
