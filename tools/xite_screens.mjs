// X_ITE's picture of each scene of a list: one headless Chromium (Debian's, WebGL through SwiftShader), one
// page holding an <x3d-canvas> of the given size, each scene loaded into it in turn and the canvas saved as a
// PNG. Driven by tools/conformance.py --browsers, which frames every scene first (a Viewpoint and a
// Background put in a copy), so X_ITE gets the same camera and background as view3dscene and vrmlray.
//
//   node tools/xite_screens.mjs NODE_MODULES ROOT LIST OUT_DIR WIDTH HEIGHT TIMEOUT_S [TIMES]
// TIMES (e.g. "0,1.5"): X_ITE's clock is virtual, so that its pictures are of the world at given seconds
// after the load, as vrmlray's --time counts them (docs/animation.md): the scene is loaded at 0 and shown at
// each time in turn, each picture going to OUT_DIR/<path with / as __>@<time>.png. Without TIMES, X_ITE
// keeps the wall clock (its TimeSensors then run at whatever phase the date gives them).
// NODE_MODULES holds the npm packages x_ite and puppeteer-core (`npm install x_ite puppeteer-core` with
// PUPPETEER_SKIP_DOWNLOAD=1: Chromium is Debian's). LIST has one path a line, relative to ROOT; each scene's
// picture goes to OUT_DIR/<path with / as __>.png. Prints one line a scene: "PATH<TAB>ok" or
// "PATH<TAB>error: MESSAGE". The scenes are served from a server on 127.0.0.1 (X_ITE fetches its URLs,
// which file:// pages cannot).
import fs from "node:fs";
import http from "node:http";
import path from "node:path";
import { createRequire } from "node:module";

const [modules, root, listFile, outDir, width, height, timeoutS, timesArg] = process.argv.slice(2);
const TIMES = timesArg ? timesArg.split(",").map(Number) : null;
const W = Number(width), H = Number(height), TIMEOUT = Number(timeoutS) * 1000;
const puppeteer = createRequire(path.join(path.resolve(modules), "x.js"))("puppeteer-core");
const xiteDir = path.join(path.resolve(modules), "x_ite", "dist");

const TYPES = { ".js": "text/javascript", ".html": "text/html", ".css": "text/css", ".png": "image/png",
                ".jpg": "image/jpeg", ".gif": "image/gif", ".x3d": "model/x3d+xml" };
const page_html = `<!DOCTYPE html><html><head><meta charset="utf-8"><style>body{margin:0}
x3d-canvas{display:block;width:${W}px;height:${H}px}</style><script src="/x_ite/x_ite.min.js"></script></head>
<body><x3d-canvas splashScreen="false" notifications="false" contextMenu="false" timings="false"></x3d-canvas>
</body></html>`;

function serve(req, res) {
    const url = decodeURIComponent(new URL(req.url, "http://x").pathname);
    if (url === "/page.html") { res.writeHead(200, { "Content-Type": "text/html" }); res.end(page_html); return; }
    const file = url.startsWith("/x_ite/") ? path.join(xiteDir, url.slice(7)) : path.join(root, url);
    const base = url.startsWith("/x_ite/") ? xiteDir : path.resolve(root);
    if (!path.resolve(file).startsWith(base) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
        res.writeHead(404); res.end(); return;
    }
    res.writeHead(200, { "Content-Type": TYPES[path.extname(file).toLowerCase()] || "application/octet-stream" });
    fs.createReadStream(file).pipe(res);
}

function withTimeout(promise, ms, what) {
    let timer;
    return Promise.race([promise, new Promise((_, reject) => {
        timer = setTimeout(() => reject(new Error(`${what} timed out after ${ms / 1000} s`)), ms);
    })]).finally(() => clearTimeout(timer));
}

// X_ITE reads its clock from Date.now() (X3DTimeContext.advanceTime). The virtual clock starts at 0 with the
// page and holds each chosen second, creeping on by a microsecond per real millisecond: X_ITE only advances
// its events when the clock has moved, and the creep stays far below any cycleInterval a scene uses. It never
// goes back (X_ITE would stop advancing), so each scene gets a page of its own.
function virtualClock() {
    window.__vclock = { base: 0, start: performance.now() };
    Date.now = () => window.__vclock.base + (performance.now() - window.__vclock.start) * 1e-3;
}

async function setClock(page, seconds) {
    await page.evaluate((ms) => {
        window.__vclock.base = ms;
        window.__vclock.start = performance.now();
    }, seconds * 1000);
}

// Each frame must count as a new time however little the virtual clock moved: X_ITE skips a frame that
// comes sooner than 1 / MaximumFrameRate after the last, and a new world resets the option.
function everyFrameAdvances() {
    const browser = document.querySelector("x3d-canvas").browser;
    const option = browser.getBrowserOption.bind(browser);
    browser.getBrowserOption = (name) => name === "MaximumFrameRate" ? 1e9 : option(name);
}

async function openPage(browser, base) {
    const page = await browser.newPage();
    if (TIMES) await page.evaluateOnNewDocument(virtualClock);
    await page.setViewport({ width: W, height: H, deviceScaleFactor: 1 });
    await page.goto(`${base}/page.html`, { waitUntil: "load" });
    await page.waitForFunction(() => document.querySelector("x3d-canvas")?.browser !== undefined);
    if (TIMES) await page.evaluate(everyFrameAdvances);
    return page;
}

// Loads the scene, then lets X_ITE draw a few frames (textures and Inlines arrive after the scene).
async function show(page, url) {
    await page.evaluate(async (u) => {
        const canvas = document.querySelector("x3d-canvas");
        await canvas.browser.loadURL(new X3D.MFString(u));
        await new Promise((r) => setTimeout(r, 500));
        for (let i = 0; i < 3; ++i) await new Promise((r) => requestAnimationFrame(r));
    }, url);
}

async function frames(page) {
    await page.evaluate(async () => {
        await new Promise((r) => setTimeout(r, 100));
        for (let i = 0; i < 3; ++i) await new Promise((r) => requestAnimationFrame(r));
    });
}

// The scene's pictures: one at the wall clock, or one at each of TIMES.
async function pictures(page, url, stem) {
    if (!TIMES) {
        await withTimeout(show(page, url), TIMEOUT, "X_ITE");
        await page.screenshot({ path: `${stem}.png`, clip: { x: 0, y: 0, width: W, height: H } });
        return;
    }
    await withTimeout(show(page, url), TIMEOUT, "X_ITE");
    for (const t of TIMES) {
        await setClock(page, t);
        await withTimeout(frames(page), TIMEOUT, "X_ITE");
        await page.screenshot({ path: `${stem}@${t}.png`, clip: { x: 0, y: 0, width: W, height: H } });
    }
}

const server = http.createServer(serve);
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await puppeteer.launch({
    executablePath: "/usr/bin/chromium", headless: true,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
});
let page = await openPage(browser, base);
for (const rel of fs.readFileSync(listFile, "utf8").split("\n").filter((l) => l.trim())) {
    const stem = path.join(outDir, rel.replaceAll("/", "__"));
    try {
        await pictures(page, `${base}/${rel.split("/").map(encodeURIComponent).join("/")}`, stem);
        console.log(`${rel}\tok`);
        if (TIMES) {  // the next scene's clock starts at 0 again
            await page.close().catch(() => {});
            page = await openPage(browser, base);
        }
    } catch (e) {
        console.log(`${rel}\terror: ${String(e.message || e).split("\n")[0].slice(0, 200)}`);
        // A scene that hangs or breaks the page must not spoil the next one: a fresh page.
        await page.close().catch(() => {});
        page = await openPage(browser, base);
    }
}
await browser.close();
server.close();
