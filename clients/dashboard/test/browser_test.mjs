// End-to-end browser test of the dashboard: a real surfmapd on 127.0.0.1
// (temp db, port 0 + --port-file), the bottle uploaded and a friction job
// created with the real `surfmap` CLI, the dashboard server started with its
// own CLI, a throttled simulated rig (`surfmap-rig --max-commands N` in a loop
// with pauses, so the job takes ~25 s) started once the page is open, and
// Debian's Chromium driven by playwright-core:
//   - the job list shows the job; selecting it renders the map (the WebGL
//     canvas is read back: enough non-background pixels and colours) and the
//     page reports its vertex/triangle/sample counts;
//   - the progress number on the page advances while the job runs, and the map
//     follows (sample count), through ONE WatchJob shared by two open pages;
//   - a probe failure of each kind, reported by the test itself as a second
//     rig over gRPC (the dashboard is read-only): the given-up site and its
//     reason in the failure list, both failures in the event list and the
//     rig table;
//   - while running: rate and time to completion from the event log;
//   - after completion: state, counts, which rig took the samples, colour
//     selector and legend (mu on the fixed scale by default, round ticks on
//     the data range), fixed scale;
//   - a click on the surface shows QueryMap values, the nearest sample's fit
//     and its trace plot;
//   - the trace plot of a drag along y (opened from the event list) shows the
//     friction: the force along the drag separates the passes by 2 mu N,
//     where world fx (what the plot used to draw) shows none;
//   - no page errors; screenshot dashboard.png into the output folder.
//
// Environment (CTest sets them; a missing binary or browser FAILS the test):
//   SURFMAPD, SURFMAP_CLI, SURFMAP_RIG   paths of the binaries
//   SURFMAP_SCENES_DIR                   folder with bottle.obj (default clients/sim/scenes)
//   SURFMAP_TEST_OUTPUT                  where dashboard.png goes (default: the temp dir, printed)
//   CHROMIUM                             browser executable (default /usr/bin/chromium)
// Prints one "ok"/"not ok" line per check and closes with "N passed, M failed".
import assert from 'node:assert/strict';
import { execFile, spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import grpc from '@grpc/grpc-js';
import protoLoader from '@grpc/proto-loader';

const here = path.dirname(fileURLToPath(import.meta.url));
const dashboardDir = path.resolve(here, '..');
const repoRoot = path.resolve(dashboardDir, '../..');
const execFileP = promisify(execFile);

const OVERALL_TIMEOUT_MS = 240000;
const RIG_BATCH = 8;          // commands per rig run
const RIG_PAUSE_MS = 700;     // between rig runs: ~219 samples take ~25 s
const BACKGROUND = [0x0f, 0x11, 0x14];  // the view's clear colour (surface_view.js)

let passed = 0;
let failed = 0;
const children = [];
let tmpDir = null;
let browser = null;

function ok(name) {
  passed += 1;
  console.log(`ok ${passed} - ${name}`);
}

async function check(name, fn) {
  try {
    const result = await fn();
    ok(name);
    return result;
  } catch (err) {
    failed += 1;
    console.log(`not ok - ${name}`);
    console.log(`  ${String(err && err.stack ? err.stack : err).replace(/\n/g, '\n  ')}`);
    throw Object.assign(new Error(`check failed: ${name}`), { reported: true });
  }
}

function requiredFile(envName, fallback, what) {
  const file = process.env[envName] || fallback;
  if (!file) throw new Error(`${envName} is not set: the path of ${what} is needed`);
  try {
    fs.accessSync(file, fs.constants.X_OK);
  } catch {
    throw new Error(`${what} not found or not executable at ${file} (set ${envName})`);
  }
  return file;
}

function startProcess(name, command, args, logFile) {
  const log = fs.openSync(logFile, 'w');
  const child = spawn(command, args, { stdio: ['ignore', log, log] });
  child.name = name;
  child.logFile = logFile;
  child.exited = new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal })));
  children.push(child);
  return child;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function waitFor(what, pred, timeoutMs, child = null) {
  const end = Date.now() + timeoutMs;
  while (Date.now() < end) {
    const value = await pred();
    if (value) return value;
    if (child && child.exitCode !== null) {
      throw new Error(`${child.name} exited (code ${child.exitCode}) while waiting for ${what}; log:\n${fs.readFileSync(child.logFile, 'utf8')}`);
    }
    await sleep(100);
  }
  throw new Error(`timed out after ${timeoutMs} ms waiting for ${what}`);
}

async function cli(surfmap, server, args) {
  const { stdout } = await execFileP(surfmap, [...args, '--server', server, '--timeout', '20']);
  return stdout.trim();
}

// A second rig, played by the test over gRPC: leases one command of the job
// and reports it failed with this kind and reason. Returns the command.
async function failOneCommand(address, jobId, rigId, kind, reason) {
  const definition = protoLoader.loadSync(path.join(repoRoot, 'proto/surfmap/v1/surfmap.proto'),
    { keepCase: true, longs: Number, enums: String, defaults: true });
  const pkg = grpc.loadPackageDefinition(definition).surfmap.v1;
  const probe = new pkg.ProbeService(address, grpc.credentials.createInsecure());
  const unary = (method, request) => new Promise((resolve, reject) => {
    probe[method](request, { deadline: new Date(Date.now() + 10000) }, (err, res) => (err ? reject(err) : resolve(res)));
  });
  try {
    const lease = await unary('LeaseCommand', { rig_id: rigId, job_id: jobId });
    if (!lease.command) throw new Error(`${rigId}: no command to lease for job ${jobId}`);
    const answer = await unary('ReportFailure', { command_id: lease.command.command_id, rig_id: rigId, reason, kind });
    return { command: lease.command, willRetry: answer.will_retry };
  } finally {
    probe.close();
  }
}

async function stopAll() {
  if (browser) await browser.close().catch(() => {});
  for (const child of children) {
    if (child.exitCode === null && child.signalCode === null) child.kill('SIGTERM');
  }
  await Promise.race([Promise.all(children.map((c) => c.exited)), sleep(15000)]);
  for (const child of children) {
    if (child.exitCode === null && child.signalCode === null) child.kill('SIGKILL');
  }
}

function dumpLogs() {
  for (const child of children) {
    try {
      const text = fs.readFileSync(child.logFile, 'utf8').split('\n').slice(-40).join('\n');
      console.log(`--- last lines of ${child.name} (${child.logFile}) ---\n${text}`);
    } catch { /* no log */ }
  }
}

// Reads the WebGL canvas back (the renderer keeps its drawing buffer) and
// summarises it: share of non-background pixels, distinct colours, and the
// surface pixel nearest the canvas centre (a place to click).
function canvasSummaryInPage(background) {
  const gl = document.querySelector('#view canvas.surface');
  const c = document.createElement('canvas');
  c.width = gl.width;
  c.height = gl.height;
  const ctx = c.getContext('2d');
  ctx.drawImage(gl, 0, 0);
  const { data } = ctx.getImageData(0, 0, c.width, c.height);
  let nonBackground = 0;
  const colours = new Set();
  let best = null;
  let bestD = Infinity;
  for (let y = 0; y < c.height; y += 2) {
    for (let x = 0; x < c.width; x += 2) {
      const i = 4 * (y * c.width + x);
      const r = data[i]; const g = data[i + 1]; const b = data[i + 2];
      const isBg = Math.abs(r - background[0]) + Math.abs(g - background[1]) + Math.abs(b - background[2]) < 12;
      if (isBg) continue;
      nonBackground += 1;
      colours.add((r >> 3) << 10 | (g >> 3) << 5 | (b >> 3));
      // Surface pixels: coloured (not the white sample dots, not the black segments).
      const grey = Math.abs(r - g) < 10 && Math.abs(g - b) < 10;
      const d = Math.hypot(x - c.width / 2, y - c.height / 2);
      if (!grey && d < bestD) { bestD = d; best = { x, y }; }
    }
  }
  const rect = gl.getBoundingClientRect();
  return {
    width: c.width, height: c.height,
    nonBackgroundShare: nonBackground / ((c.width / 2) * (c.height / 2)),
    distinctColours: colours.size,
    clickAt: best ? { x: rect.left + (best.x * rect.width) / c.width, y: rect.top + (best.y * rect.height) / c.height } : null,
  };
}

async function main() {
  const surfmapd = requiredFile('SURFMAPD', path.join(repoRoot, 'build/server/service/surfmapd'), 'surfmapd');
  const surfmap = requiredFile('SURFMAP_CLI', path.join(repoRoot, 'build/clients/cli/surfmap'), 'the surfmap CLI');
  const rig = requiredFile('SURFMAP_RIG', path.join(repoRoot, 'build/clients/rig/surfmap-rig'), 'surfmap-rig');
  const chromiumPath = requiredFile('CHROMIUM', '/usr/bin/chromium', 'Chromium (Debian package chromium)');
  const scenes = process.env.SURFMAP_SCENES_DIR || path.join(repoRoot, 'clients/sim/scenes');
  const bottle = path.join(scenes, 'bottle.obj');
  if (!fs.existsSync(bottle)) throw new Error(`scene mesh ${bottle} is missing (set SURFMAP_SCENES_DIR)`);
  let chromium;
  try {
    ({ chromium } = await import('playwright-core'));
  } catch (err) {
    throw new Error(`playwright-core is not installed in ${dashboardDir}/node_modules (run npm ci there): ${err.message}`);
  }

  tmpDir = fs.mkdtempSync(path.join(os.tmpdir(), 'surfmap-dashboard-test-'));
  const outDir = process.env.SURFMAP_TEST_OUTPUT || tmpDir;
  fs.mkdirSync(outDir, { recursive: true });

  // ---- surfmapd, object, job
  const portFile = path.join(tmpDir, 'port');
  const server = startProcess('surfmapd', surfmapd,
    ['--listen', '127.0.0.1:0', '--db', path.join(tmpDir, 'surfmap.db'), '--port-file', portFile, '--log-format', 'text'],
    path.join(tmpDir, 'surfmapd.log'));
  const port = await check('surfmapd starts on a free loopback port', () => waitFor('the port file',
    () => (fs.existsSync(portFile) && fs.readFileSync(portFile, 'utf8').trim()) || null, 30000, server));
  const address = `127.0.0.1:${port}`;
  const objectId = Number(await cli(surfmap, address, ['object', 'upload', bottle, '--name', 'bottle']));
  const jobId = Number(await cli(surfmap, address, ['job', 'create', '--object', String(objectId), '--property', 'friction',
    '--mode', 'adaptive', '--coarsest', '0', '--finest', '1', '--map-level', '1', '--threshold', '2', '--seed', '2001']));
  await check(`bottle uploaded (object ${objectId}) and friction job created (job ${jobId})`, () => {
    assert.ok(objectId > 0 && jobId > 0);
  });

  // ---- the dashboard server, through its CLI
  const dashboard = startProcess('dashboard', process.execPath,
    [path.join(dashboardDir, 'server.js'), '--server', address, '--listen', '127.0.0.1:0'], path.join(tmpDir, 'dashboard.log'));
  const url = await check('the dashboard server starts and prints its URL', () => waitFor('the dashboard URL', () => {
    const m = /listening on (http:\/\/\S+)/.exec(fs.readFileSync(dashboard.logFile, 'utf8'));
    return m ? m[1] : null;
  }, 20000, dashboard));

  // ---- the browser
  browser = await chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    // Software WebGL (SwiftShader through ANGLE): no GPU on test machines.
    // The rest keep Chromium off the network (closed on test machines).
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--disable-quic', '--no-first-run'],
  });
  const context = await browser.newContext({ viewport: { width: 1400, height: 860 } });
  const pageErrors = [];
  const page = await context.newPage();
  page.on('pageerror', (e) => pageErrors.push(`pageerror: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') pageErrors.push(`console: ${m.text()}`); });
  await page.goto(url);

  await check('the job list shows the job; clicking it selects it', async () => {
    const item = page.locator(`#job-list li[data-job-id="${jobId}"]`);
    await item.waitFor({ timeout: 15000 });
    assert.match(await item.innerText(), new RegExp(`job ${jobId} · bottle`));
    assert.match(await item.innerText(), /RUNNING/);
    await item.click();
    await page.waitForFunction((id) => document.querySelector('#progress').dataset.job === String(id), jobId, { timeout: 15000 });
    assert.match(await page.locator('#object-list').innerText(), /bottle/);
  });

  const meshCounts = await check('the surface mesh loads (vertex and triangle counts reported)', async () => {
    await page.waitForFunction(() => Number(document.querySelector('#view').dataset.vertexCount) > 0, null, { timeout: 20000 });
    const d = await page.evaluate(() => ({ ...document.querySelector('#view').dataset }));
    assert.equal(d.webgl, 'ok', 'WebGL is available');
    // One Loop step of the closed triangle mesh in bottle.obj: V + E vertices
    // (E = 3F / 2) and 4F triangles.
    const obj = fs.readFileSync(bottle, 'utf8').split('\n');
    const v0 = obj.filter((line) => line.startsWith('v ')).length;
    const f0 = obj.filter((line) => line.startsWith('f ')).length;
    assert.equal(Number(d.vertexCount), v0 + (3 * f0) / 2, 'bottle at level 1');
    assert.equal(Number(d.triangleCount), 4 * f0);
    assert.equal(Number(d.sampleCount), 0, 'nothing measured yet');
    return d;
  });
  void meshCounts;

  // A second page on the same job: both must share one WatchJob stream.
  const page2 = await context.newPage();
  await page2.goto(`${url}/#job=${jobId}`);
  await check('two open pages share ONE WatchJob stream for the job', async () => {
    const status = await waitFor('two subscribers', async () => {
      const s = await (await fetch(`${url}/api/status`)).json();
      const w = s.watches.filter((x) => x.job_id === jobId);
      return w.length === 1 && w[0].subscribers === 2 ? s : null;
    }, 15000);
    assert.equal(status.watches.length, 1);
  });

  // ---- two probe failures from a second rig, before the simulated rig runs
  const UNREACHABLE_REASON = 'outside the workspace of this arm (browser test)';
  const TRANSIENT_REASON = 'force limit tripped (browser test)';
  const failures = await check('a second rig reports one unreachable and one transient failure over gRPC', async () => {
    const unreachable = await failOneCommand(address, jobId, 'failing-rig', 'FAILURE_KIND_UNREACHABLE', UNREACHABLE_REASON);
    const transient = await failOneCommand(address, jobId, 'failing-rig', 'FAILURE_KIND_TRANSIENT', TRANSIENT_REASON);
    assert.equal(transient.willRetry, true, 'a transient failure is retried');
    // The proto says an unreachable site is given up at once; surfmapd (main
    // at d37ca38) records the kind but re-queues the site like a transient
    // failure. The page must show what the server answered either way.
    return { unreachable, transient };
  });

  await check('the failure list shows each failed site with the reason the rig gave; events and rig table show both failures', async () => {
    // The last failure of each site (a re-queued site may be leased again at once).
    const lastPerSite = new Map();
    for (const [failure, reason] of [[failures.unreachable, UNREACHABLE_REASON], [failures.transient, TRANSIENT_REASON]]) {
      lastPerSite.set(`${failure.command.site.level}/${failure.command.site.vertex}`, { site: failure.command.site, failure, reason });
    }
    for (const { site, failure, reason } of lastPerSite.values()) {
      const item = page.locator(`#failure-list li[data-level="${site.level}"][data-vertex="${site.vertex}"]`);
      await page.waitForFunction(([l, v, r]) => document.querySelector(`#failure-list li[data-level="${l}"][data-vertex="${v}"]`)?.textContent.includes(r),
        [site.level, site.vertex, reason], { timeout: 15000 });
      const state = await item.getAttribute('data-state');
      if (failure.willRetry) assert.ok(['ISSUED', 'PENDING'].includes(state), `site L${site.level} v${site.vertex} is re-queued: ${state}`);
      else assert.equal(state, 'FAILED', `site L${site.level} v${site.vertex}`);
      assert.match(await item.innerText(), failure.willRetry ? /last failure: / : /given up after \d+ attempts?: /);
    }
    await page.waitForFunction(() => document.querySelectorAll('#event-list li[data-kind="probe_failed"]').length === 2, null, { timeout: 10000 });
    const texts = await page.locator('#event-list li[data-kind="probe_failed"]').allInnerTexts();
    const retryText = (f) => (f.willRetry ? 'will retry' : 'given up');
    assert.ok(texts.some((t) => t.includes(`failed at failing-rig (unreachable, ${retryText(failures.unreachable)}): ${UNREACHABLE_REASON}`)), texts.join('\n'));
    assert.ok(texts.some((t) => t.includes(`failed at failing-rig (transient, will retry): ${TRANSIENT_REASON}`)), texts.join('\n'));
    const rig = page.locator('#rig-table tr[data-rig="failing-rig"]');
    assert.equal(await rig.getAttribute('data-failed'), '2');
    assert.equal(await rig.getAttribute('data-accepted'), '0');
    await page.screenshot({ path: path.join(outDir, 'dashboard_failures.png') });
  });

  // ---- the throttled rig, started now that the pages are open
  let rigRuns = 0;
  let rigDone = false;
  let rigDoneAt = 0;
  const rigLoop = (async () => {
    for (;;) {
      const { code, stdout, stderr } = await new Promise((resolve) => {
        execFile(rig, ['--server', address, '--sim', 'bottle', '--job', String(jobId), '--rig-id', 'browser-test',
          '--max-commands', String(RIG_BATCH), '--quiet'], (err, out, errOut) => resolve({ code: err ? err.code ?? 1 : 0, stdout: out, stderr: errOut }));
      });
      rigRuns += 1;
      if (code !== 0) throw new Error(`surfmap-rig failed (exit ${code}): ${stdout}${stderr}`);
      if (/job finished/.test(stdout + stderr)) break;
      await sleep(RIG_PAUSE_MS);
    }
    rigDone = true;
    rigDoneAt = Date.now();
  })();
  let rigError = null;
  rigLoop.catch((err) => { rigError = err; rigDoneAt = Date.now(); });

  const observed = await check('the progress number advances on the page while the job runs (live)', async () => {
    const seen = [];
    const started = Date.now();
    while (Date.now() - started < 150000) {
      const d = await page.evaluate(() => ({
        measured: Number(document.querySelector('#progress').dataset.measured),
        state: document.querySelector('#progress').dataset.state,
        samples: Number(document.querySelector('#view').dataset.sampleCount),
        rate: document.querySelector('#rate-panel').dataset.rate,
        etaS: document.querySelector('#rate-panel').dataset.etaS,
      }));
      if (seen.length === 0 || d.measured !== seen.at(-1).measured || d.state !== seen.at(-1).state) seen.push(d);
      if (d.state === 'COMPLETED') break;
      // The rig finished: the page has 15 s to show it, not the whole budget.
      if (rigDoneAt && Date.now() - rigDoneAt > 15000) break;
      await sleep(300);
    }
    if (rigError) throw rigError;
    const running = seen.filter((s) => s.state === 'RUNNING' && s.measured > 0);
    assert.ok(running.length >= 4, `at least 4 distinct progress values seen while RUNNING; saw ${JSON.stringify(seen)}`);
    for (let i = 1; i < seen.length; ++i) assert.ok(seen[i].measured >= seen[i - 1].measured, 'progress never goes back');
    assert.ok(running.some((s) => s.samples > 0 && s.samples < seen.at(-1).measured), 'the map showed samples while running');
    // The rig runs 8 commands, pauses 0.7 s: a few traces per second.
    const rated = running.filter((s) => Number(s.rate) > 0 && Number(s.etaS) > 0);
    assert.ok(rated.length >= 2, `rate and time to completion shown while running; saw ${JSON.stringify(running.slice(-4))}`);
    for (const s of rated) assert.ok(Number(s.rate) > 0.5 && Number(s.rate) < 1000, `rate ${s.rate} traces/s`);
    assert.equal(seen.at(-1).state, 'COMPLETED', `the job completed; saw ${JSON.stringify(seen.slice(-3))}`);
    return seen;
  });
  await rigLoop;
  assert.ok(rigDone);
  console.log(`# ${observed.length} distinct progress states seen, rig ran ${rigRuns} times`);

  const final = await check('after completion the page shows the full map: every measured sample is drawn', async () => {
    const api = await (await fetch(`${url}/api/jobs/${jobId}`)).json();
    assert.equal(api.job.state, 'COMPLETED');
    const measured = api.job.progress.measured;
    await page.waitForFunction((n) => Number(document.querySelector('#view').dataset.sampleCount) === n, measured, { timeout: 15000 });
    const d = await page.evaluate(() => ({ ...document.querySelector('#view').dataset, ...document.querySelector('#progress').dataset }));
    assert.equal(Number(d.measured), measured);
    assert.equal(Number(d.total), api.job.progress.total, 'measured + given up');
    assert.equal(d.state, 'COMPLETED');
    assert.match(await page.locator(`#job-list li[data-job-id="${jobId}"]`).innerText(), /COMPLETED/);
    return { measured, d };
  });

  await check('the rig table says which rig took the samples; the time to completion says the job is done', async () => {
    const rig = page.locator('#rig-table tr[data-rig="browser-test"]');
    await page.waitForFunction((n) => document.querySelector('#rig-table tr[data-rig="browser-test"]')?.dataset.accepted === String(n),
      final.measured, { timeout: 10000 });
    assert.equal(await rig.getAttribute('data-failed'), '0');
    assert.match(await page.locator('#rate-text').innerText(), /time to completion: job completed/);
    assert.equal(await page.locator('#rate-panel').getAttribute('data-eta-s'), '');
  });

  const summary = await check('the WebGL canvas shows the coloured surface (pixels read back)', async () => {
    await sleep(300);  // the last frame after the final map
    const s = await page.evaluate(canvasSummaryInPage, BACKGROUND);
    assert.ok(s.nonBackgroundShare > 0.05, `surface covers ${(100 * s.nonBackgroundShare).toFixed(1)}% of the canvas`);
    assert.ok(s.distinctColours >= 20, `${s.distinctColours} distinct colours (the glass and sandpaper regions and the shading)`);
    assert.ok(s.clickAt, 'a surface pixel to click');
    return s;
  });
  console.log(`# canvas ${summary.width}x${summary.height}: ${(100 * summary.nonBackgroundShare).toFixed(1)}% surface, ${summary.distinctColours} colours`);

  const tickTexts = () => page.locator('#legend-ticks span').allInnerTexts();
  await check('mu starts on the fixed 0..1 scale; the data range gets round, distinct ticks; the selector recolours', async () => {
    assert.equal(await page.locator('#legend').isVisible(), true);
    assert.match(await page.locator('#legend-title').innerText(), /friction coefficient mu/);
    assert.equal(await page.locator('#scale-mode').inputValue(), 'fixed');
    assert.deepEqual(await tickTexts(), ['0.0', '0.2', '0.4', '0.6', '0.8', '1.0']);
    await page.selectOption('#scale-mode', 'data');
    await page.waitForFunction(() => document.querySelector('#legend-ticks span').textContent !== '0.0');
    const ticks = await tickTexts();
    assert.equal(new Set(ticks).size, ticks.length, `distinct ticks ${ticks}`);
    const values = ticks.map(Number);
    assert.ok(values.length >= 3 && values.length <= 6, `${values.length} ticks`);
    assert.ok(values[0] >= 0.1 && values.at(-1) <= 0.55, `ticks inside the data range (glass ~0.13 .. sandpaper ~0.5): ${ticks}`);
    await page.selectOption('#quantity', 'mu_uncertainty');
    await page.waitForFunction(() => /uncertainty/.test(document.querySelector('#legend-title').textContent));
    assert.equal(await page.locator('#scale-mode').inputValue(), 'data', 'the other quantities start on the data range');
    await page.selectOption('#quantity', 'mu');
    assert.equal(await page.locator('#scale-mode').inputValue(), 'data', 'the mode is kept per quantity');
  });

  await check('a fixed colour scale sets the legend to its limits; a bad limit is named and falls back', async () => {
    await page.selectOption('#scale-mode', 'fixed');
    await page.waitForFunction(() => document.querySelector('#legend-ticks span:last-child').textContent === '1.0');
    await page.fill('#scale-max', '0.3');
    await page.waitForFunction(() => document.querySelector('#legend-ticks span:last-child').textContent === '0.3');
    assert.match(await page.locator('#scale-note').innerText(), /vertices outside the scale/);
    await page.fill('#scale-max', '-1');
    await page.waitForFunction(() => /min < max/.test(document.querySelector('#scale-note').textContent));
    const fallback = (await tickTexts()).map(Number);
    assert.ok(fallback.at(-1) > 0.3 && fallback.at(-1) <= 0.55, `fell back to the data range, top tick ${fallback.at(-1)}`);
    await page.fill('#scale-max', '1');
    await page.waitForFunction(() => document.querySelector('#scale-note').textContent === '');
  });

  await check('a click on the surface shows the interpolated values, the nearest fit and its trace', async () => {
    await page.mouse.click(summary.clickAt.x, summary.clickAt.y);
    await page.waitForFunction(() => document.querySelector('#point-info').dataset.mu !== undefined, null, { timeout: 10000 });
    const mu = Number(await page.evaluate(() => document.querySelector('#point-info').dataset.mu));
    assert.ok(mu > 0.05 && mu < 0.7, `mu at the clicked point ${mu}`);
    assert.match(await page.locator('#point-body').innerText(), /mu\s+0\.\d{4} ± 0\.\d{4}/);
    await page.waitForSelector('#trace-plot svg polyline', { timeout: 10000 });
    const plot = await page.evaluate(() => ({
      traceId: document.querySelector('#trace-plot').dataset.traceId,
      lines: document.querySelectorAll('#trace-plot svg polyline').length,
      pairs: Number(document.querySelector('#trace-plot').dataset.pairCount),
      dots: document.querySelectorAll('#trace-plot svg g.pair-mu circle').length,
      sample: document.querySelector('#sample-body').innerText,
    }));
    assert.ok(Number(plot.traceId) > 0);
    assert.equal(plot.lines, 6, 'normal, along the drag and lateral, forward and reverse');
    assert.ok(plot.pairs > 50, `per-pair mu from GetSample include_series (${plot.pairs} pairs)`);
    assert.equal(plot.dots, plot.pairs, 'one dot per pair');
    assert.match(plot.sample, new RegExp(`^trace\\s+${plot.traceId} `, 'm'));
    assert.match(plot.sample, /mu \(mean ± std\)\s+0\.\d{4} ± 0\.\d{4}/);
    assert.match(plot.sample, /^rig\s+browser-test$/m);
  });

  await check('the trace plot of a drag along y shows the friction (opened from the event list)', async () => {
    const { samples } = await (await fetch(`${url}/api/jobs/${jobId}/samples`)).json();
    // The newest drag along y, so its event is among the list's recent ones.
    const alongY = samples.filter((x) => Math.abs(x.drag_direction.y) > 0.9).sort((a, b) => b.command_id - a.command_id);
    assert.ok(alongY.length > 0, `a drag along y among ${samples.length} samples`);
    const sample = alongY[0];
    const row = page.locator(`#event-list li[data-command-id="${sample.command_id}"]`);
    await row.scrollIntoViewIfNeeded();
    await row.click();
    await page.waitForFunction((id) => document.querySelector('#trace-plot').dataset.traceId === String(id), sample.trace_id, { timeout: 10000 });
    const d = await page.evaluate(() => ({ ...document.querySelector('#trace-plot').dataset }));
    const mu = sample.fit.friction.mu;
    assert.equal(d.normalSource, 'pairs');
    assert.ok(Number(d.alongFwd) < 0 && Number(d.alongRev) > 0, `friction opposes each pass: forward ${d.alongFwd} N, reverse ${d.alongRev} N`);
    assert.ok(Math.abs(Number(d.plotMu) - mu) < 0.1 * mu + 0.005, `the plotted forces give mu ${d.plotMu}; the fit says ${mu}`);
    assert.ok(Math.abs(Number(d.normalMean) - 5) < 0.5, `normal force ${d.normalMean} N (5 N commanded)`);
    assert.ok(Math.abs(Number(d.lateralMean)) < 0.1 * mu * 5, `lateral ${d.lateralMean} N`);
    // What the old plot drew (world fx) shows no friction on this drag.
    const { trace } = await (await fetch(`${url}/api/traces/${sample.trace_id}`)).json();
    const meanFx = (phase) => {
      const v = trace.fx.filter((_, i) => trace.phases[i] === phase);
      return v.reduce((a, b) => a + b, 0) / v.length;
    };
    const worldGap = Math.abs(meanFx('rev') - meanFx('fwd')) / 2;
    assert.ok(worldGap < 0.2 * mu * 5, `world fx separates the passes by only ${worldGap.toFixed(3)} N (friction ${(mu * 5).toFixed(3)} N)`);
    assert.match(await page.locator('#sample-body').innerText(), /drag direction\s+-?0\.\d{3}, -?1\.000, -?0\.\d{3}/);
    await page.screenshot({ path: path.join(outDir, 'dashboard_drag_along_y.png') });
  });

  await check('screenshot saved', async () => {
    const file = path.join(outDir, 'dashboard.png');
    await page.screenshot({ path: file });
    assert.ok(fs.statSync(file).size > 20000);
    console.log(`# screenshot: ${file}`);
  });

  await check('the live streams close once the job ended and nobody watches', async () => {
    await page2.close();
    await page.close();
    await waitFor('no open WatchJob', async () => (await (await fetch(`${url}/api/status`)).json()).watches.length === 0, 10000);
  });

  await check('no errors in the page', () => {
    assert.deepEqual(pageErrors, []);
  });
  void final;
}

const guard = setTimeout(() => {
  console.log(`not ok - the test did not finish within ${OVERALL_TIMEOUT_MS / 1000} s`);
  dumpLogs();
  stopAll().finally(() => process.exit(1));
}, OVERALL_TIMEOUT_MS);

let exitCode = 0;
try {
  await main();
} catch (err) {
  exitCode = 1;
  if (!err.reported) {
    failed += 1;
    console.log(`not ok - ${err.message}`);
  }
  dumpLogs();
} finally {
  clearTimeout(guard);
  await stopAll();
  if (tmpDir && exitCode === 0 && process.env.SURFMAP_TEST_OUTPUT) fs.rmSync(tmpDir, { recursive: true, force: true });
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(exitCode);
