// Shared scaffolding of the headless Chromium tests (js.three_grid, js.three_compact): a local HTTP
// server over a few directories, a POST /result endpoint for the page's report, and one fresh headless Chromium per page (SwiftShader), killed after the report or 180 s.
import fs from 'node:fs';
import path from 'node:path';
import http from 'node:http';
import { spawn } from 'node:child_process';

const TYPES = { '.html': 'text/html', '.mjs': 'text/javascript', '.js': 'text/javascript', '.json': 'application/json',
  '.glb': 'model/gltf-binary' };

// roots: { '/prefix/': directory }. Returns { runPage(html, extraArgs, tag, doneMarker), close() }:
// runPage resolves to the page's JSON report, or null after 180 s; it checks (with `check`) that
// the page reported, that Chromium's log has no console error and that the page's console line
// `doneMarker` reached the log (so the console check can fail).
export async function chromiumPages({ roots, work, chromium, check }) {
  let resolveResult;
  const served = [];
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://127.0.0.1');
    if (req.method === 'POST' && url.pathname === '/result') {
      let body = '';
      req.on('data', (c) => { body += c; });
      req.on('end', () => { res.end('ok'); resolveResult(body); });
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
    const timeout = new Promise((resolve) => { timer = setTimeout(() => resolve(null), 180000); });
    const body = await Promise.race([result, timeout]);
    clearTimeout(timer);
    try { process.kill(-browser.pid, 'SIGKILL'); } catch { /* already gone */ }
    fs.rmSync(profile, { recursive: true, force: true });
    fs.writeFileSync(path.join(work, `chromium_stderr_${tag}.txt`), stderr);
    check(body !== null, `${tag}: the page reported within 180 s`);
    if (body === null) {
      console.log(`served: ${served.join(' ')}`);
      console.log(stderr.split('\n').slice(-30).join('\n'));
      return null;
    }
    const consoleErrors = stderr.split('\n').filter((l) => /CONSOLE/.test(l) && /(Uncaught|Error)/.test(l));
    for (const l of consoleErrors) console.log(`  chromium: ${l}`);
    check(consoleErrors.length === 0, `${tag}: no console error in Chromium's log`);
    check(new RegExp(`CONSOLE.*${doneMarker}`).test(stderr), `${tag}: the page's console output reaches Chromium's log (so the check above can fail)`);
    return JSON.parse(body);
  }
  return { runPage, close: () => server.close() };
}
