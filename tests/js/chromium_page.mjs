// Shared scaffolding of the headless Chromium tests (js.browser, js.latlong_three, js.three_grid,
// js.three_compact, js.wgsl): a loopback HTTP server (127.0.0.1, ephemeral port) over a few
// directories plus the test's own routes, a POST /result endpoint for the page's report, and one
// fresh headless Chromium per page (SwiftShader, fresh profile), killed after the report or the
// timeout.
import fs from 'node:fs';
import path from 'node:path';
import http from 'node:http';
import { spawn } from 'node:child_process';

const TYPES = { '.html': 'text/html', '.mjs': 'text/javascript', '.js': 'text/javascript', '.json': 'application/json',
  '.glb': 'model/gltf-binary', '.wgsl': 'text/plain' };

// The whole body of a request, as a Buffer.
export const readBody = (req) => new Promise((resolve) => {
  const chunks = [];
  req.on('data', (c) => chunks.push(c));
  req.on('end', () => resolve(Buffer.concat(chunks)));
});

// roots: { '/prefix/': directory }; routes: { 'METHOD /path': async (req, res) => ... }, the test's
// own endpoints. Returns { runPage(html, extraArgs, tag, doneMarker), close() }: runPage
// opens /test/<html> and resolves to the page's JSON report, or null after timeoutS seconds; it
// checks (with `check`) that the page reported, that Chromium's log has no console error and that
// the page's console line `doneMarker` reached the log (so the console check can fail), and that
// the report carries the `errors` list of browser/collect_errors.js.
export async function chromiumPages({ roots, work, chromium, check, routes = {}, timeoutS = 180 }) {
  let resolveResult;
  const served = [];
  const server = http.createServer(async (req, res) => {
    const url = new URL(req.url, 'http://127.0.0.1');
    if (req.method === 'POST' && url.pathname === '/result') {
      const body = await readBody(req);
      res.end('ok');
      resolveResult(body.toString());
      return;
    }
    const route = routes[`${req.method} ${url.pathname}`];
    if (route) {
      await route(req, res);
      return;
    }
    const pathname = decodeURIComponent(url.pathname);
    for (const [prefix, dir] of Object.entries(roots)) {
      if (!pathname.startsWith(prefix)) continue;
      const file = path.resolve(dir, '.' + pathname.slice(prefix.length - 1));
      if (!file.startsWith(dir + path.sep) || !fs.existsSync(file) || !fs.statSync(file).isFile()) break;
      served.push(pathname);
      res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] ?? 'application/octet-stream', 'Cache-Control': 'no-store' });
      res.end(fs.readFileSync(file));
      return;
    }
    res.writeHead(404);
    res.end();
    served.push(`404 ${pathname}`);
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const port = server.address().port;
  async function runPage(html, extraArgs, tag, doneMarker) {
    const result = new Promise((resolve) => { resolveResult = resolve; });
    const profile = fs.mkdtempSync(path.join(work, 'chromium-profile-'));
    const args = ['--headless=new', '--no-sandbox', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--disable-default-apps', '--disable-extensions', `--user-data-dir=${profile}`,
      '--enable-unsafe-swiftshader', '--enable-logging=stderr', '--v=0', ...extraArgs, `http://127.0.0.1:${port}/test/${html}`];
    const browser = spawn(chromium, args, { detached: true, stdio: ['ignore', 'ignore', 'pipe'] });
    let stderr = '';
    browser.stderr.on('data', (c) => { stderr += c; });
    let timer;
    const timeout = new Promise((resolve) => { timer = setTimeout(() => resolve(null), timeoutS * 1000); });
    const body = await Promise.race([result, timeout]);
    clearTimeout(timer);
    // The page logs its last line just before posting: give Chromium's log a moment to carry it.
    const marker = new RegExp(`CONSOLE.*${doneMarker}`);
    for (let i = 0; i < 50 && body !== null && !marker.test(stderr); i++) await new Promise((r) => setTimeout(r, 100));
    try { process.kill(-browser.pid, 'SIGKILL'); } catch { /* already gone */ }
    fs.rmSync(profile, { recursive: true, force: true });
    fs.writeFileSync(path.join(work, `chromium_stderr_${tag}.txt`), stderr);
    check(body !== null, `${tag}: the page reported within ${timeoutS} s`);
    if (body === null) {
      console.log(`served: ${served.join(' ')}`);
      console.log(stderr.split('\n').slice(-30).join('\n'));
      return null;
    }
    const consoleErrors = stderr.split('\n').filter((l) => /CONSOLE/.test(l) && /(Uncaught|Error)/.test(l));
    for (const l of consoleErrors) console.log(`  chromium: ${l}`);
    check(consoleErrors.length === 0, `${tag}: no console error in Chromium's log`);
    check(marker.test(stderr), `${tag}: the page's console output reaches Chromium's log (so the check above can fail)`);
    const report = JSON.parse(body);
    check(Array.isArray(report.errors), `${tag}: the page's error collector (browser/collect_errors.js) ran`);
    return report;
  }
  return { runPage, close: () => server.close() };
}
