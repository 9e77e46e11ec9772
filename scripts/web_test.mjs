// Drives headless Chromium (Playwright) over the site `scripts/web.sh` built, served here on
// 127.0.0.1, once per backend: waits for the page's report line
// `rwt-web: backend=B instances=N frames=F frame_ms=T`, saves a screenshot, and fails on a
// console error, an uncaught exception (a Rust panic is one), a backend other than the one
// asked for, N = 0, or no report within the time limit. The page's whole console goes to
// OUT_DIR/BACKEND.log. The blank-canvas check reads the screenshots afterwards (web_test.sh).
//
//   node scripts/web_test.mjs SITE OUT_DIR BACKEND...
import { chromium } from "playwright-core";
import { createServer } from "node:http";
import { appendFileSync, writeFileSync } from "node:fs";
import { readFile } from "node:fs/promises";
import { extname, join, normalize } from "node:path";

const [site, out, ...backends] = process.argv.slice(2);
const LIMIT_S = Number(process.env.RWT_WEB_LIMIT_S ?? 900);
const SHOT_S = Number(process.env.RWT_WEB_SHOT_S ?? 180);
// The share of the vegetation the page grows (its `?detail=`): SwiftShader pays for every
// instance drawn, tens of microseconds each, so the whole world takes about 40 s a frame.
const DETAIL = process.env.RWT_WEB_DETAIL ?? "0.02";
// Frames the page times once settled (its `?frames=`; 120 unless set): fewer for pictures
// of a denser world, whose frames take many seconds in SwiftShader.
const FRAMES = process.env.RWT_WEB_FRAMES ? `&frames=${process.env.RWT_WEB_FRAMES}` : "";
// The page's size: RWT_WEB_SIZE=1280x720 for pictures; smaller renders faster on SwiftShader.
const [WIDTH, HEIGHT] = (process.env.RWT_WEB_SIZE ?? "640x360").split("x").map(Number);
const REPORT = /^rwt-web: backend=(\S+) instances=(\d+) frames=(\d+) frame_ms=([\d.]+)$/;
const TYPES = {
  ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm",
  ".glb": "model/gltf-binary", ".png": "image/png", ".ron": "text/plain",
};
// Chromium without a GPU: WebGL2 through ANGLE on SwiftShader, WebGPU through Dawn on
// SwiftShader's Vulkan; no network but the page's (this machine's is closed).
const COMMON = [
  "--headless=new", "--no-sandbox", "--no-first-run", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--disable-quic",
  "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
];
const FLAGS = {
  webgl2: COMMON,
  webgpu: [...COMMON, "--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader"],
};

function serve(root) {
  const server = createServer(async (req, res) => {
    const path = normalize(decodeURIComponent(new URL(req.url, "http://x").pathname));
    if (path.includes("..")) return res.writeHead(403).end();
    try {
      const body = await readFile(join(root, path === "/" ? "index.html" : path));
      res.writeHead(200, { "content-type": TYPES[extname(path)] ?? "application/octet-stream" });
      res.end(body);
    } catch {
      res.writeHead(404).end();
    }
  });
  return new Promise((ok) => server.listen(0, "127.0.0.1", () => ok(server)));
}

async function run(port, backend) {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
    headless: true,
    args: FLAGS[backend],
  });
  const problems = [];
  const logFile = join(out, `${backend}.log`);
  writeFileSync(logFile, "");
  let report = null;
  const started = Date.now();
  try {
    const page = await browser.newPage({ viewport: { width: WIDTH, height: HEIGHT } });
    const reported = new Promise((ok) => {
      page.on("console", (msg) => {
        const text = msg.text();
        appendFileSync(logFile, `${((Date.now() - started) / 1000).toFixed(1)} ${msg.type()}: ${text}\n`);
        // tracing's lines carry a level, a place and CSS: keep the message.
        const line = text.match(/rwt-web: [^%]*?(?= color:|$)/);
        if (line) console.log(`[${backend}] ${line[0]}`);
        if (msg.type() === "error") problems.push(`console error: ${text}`);
        const m = text.match(REPORT);
        if (m) ok((report = m));
      });
    });
    page.on("pageerror", (e) => problems.push(`uncaught: ${e.message}`));
    page.on("response", (r) => r.status() >= 400 && problems.push(`HTTP ${r.status()}: ${r.url()}`));
    await page.goto(`http://127.0.0.1:${port}/index.html?backend=${backend}&clean&detail=${DETAIL}${FRAMES}`);
    const limit = new Promise((ok) => setTimeout(ok, LIMIT_S * 1000));
    const failed = new Promise((ok) => {
      const poll = setInterval(() => problems.length && (clearInterval(poll), ok()), 500);
    });
    await Promise.race([reported, limit, failed]);
    // The second report line (culling, slowest frame) follows the first.
    await page.waitForTimeout(2000);
    // A busy page (the module compiling, SwiftShader drawing) is slow to capture: up to
    // RWT_WEB_SHOT_S seconds (a denser world's frames take tens of seconds each).
    await page
      .screenshot({ path: join(out, `${backend}.png`), timeout: SHOT_S * 1000 })
      .catch((e) => problems.push(`no screenshot: ${e.message.split("\n")[0]}`));
  } finally {
    await browser.close();
  }
  const seconds = ((Date.now() - started) / 1000).toFixed(0);
  if (!report) problems.push(`no report line within ${LIMIT_S} s`);
  else if (report[1] !== backend) problems.push(`backend ${report[1]}, not ${backend}`);
  else if (Number(report[2]) === 0) problems.push("no instances (N = 0)");
  console.log(`[${backend}] ${problems.length ? "FAILED" : "ok"} in ${seconds} s`);
  problems.forEach((p) => console.log(`[${backend}]   ${p}`));
  return problems.length === 0;
}

const server = await serve(site);
let ok = true;
for (const backend of backends) ok = (await run(server.address().port, backend)) && ok;
server.close();
process.exit(ok ? 0 : 1);
