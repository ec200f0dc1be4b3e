// X_ITE's picture of each scene of a list: one headless Chromium (Debian's, WebGL through SwiftShader), one
// page holding an <x3d-canvas> of the given size, each scene loaded into it in turn and the canvas saved as a
// PNG. Driven by tools/conformance.py --browsers, which frames every scene first (a Viewpoint and a
// Background put in a copy), so X_ITE gets the same camera and background as view3dscene and vrmlray.
//
//   node tools/xite_screens.mjs NODE_MODULES ROOT LIST OUT_DIR WIDTH HEIGHT TIMEOUT_S
// NODE_MODULES holds the npm packages x_ite and puppeteer-core (`npm install x_ite puppeteer-core` with
// PUPPETEER_SKIP_DOWNLOAD=1: Chromium is Debian's). LIST has one path a line, relative to ROOT; each scene's
// picture goes to OUT_DIR/<path with / as __>.png. Prints one line a scene: "PATH<TAB>ok" or
// "PATH<TAB>error: MESSAGE". The scenes are served from a server on 127.0.0.1 (X_ITE fetches its URLs,
// which file:// pages cannot).
import fs from "node:fs";
import http from "node:http";
import path from "node:path";
import { createRequire } from "node:module";

const [modules, root, listFile, outDir, width, height, timeoutS] = process.argv.slice(2);
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

async function openPage(browser, base) {
    const page = await browser.newPage();
    await page.setViewport({ width: W, height: H, deviceScaleFactor: 1 });
    await page.goto(`${base}/page.html`, { waitUntil: "load" });
    await page.waitForFunction(() => document.querySelector("x3d-canvas")?.browser !== undefined);
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

const server = http.createServer(serve);
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await puppeteer.launch({
    executablePath: "/usr/bin/chromium", headless: true,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
});
let page = await openPage(browser, base);
for (const rel of fs.readFileSync(listFile, "utf8").split("\n").filter((l) => l.trim())) {
    const out = path.join(outDir, rel.replaceAll("/", "__") + ".png");
    try {
        await withTimeout(show(page, `${base}/${rel.split("/").map(encodeURIComponent).join("/")}`),
                          TIMEOUT, "X_ITE");
        await page.screenshot({ path: out, clip: { x: 0, y: 0, width: W, height: H } });
        console.log(`${rel}\tok`);
    } catch (e) {
        console.log(`${rel}\terror: ${String(e.message || e).split("\n")[0].slice(0, 200)}`);
        // A scene that hangs or breaks the page must not spoil the next one: a fresh page.
        await page.close().catch(() => {});
        page = await openPage(browser, base);
    }
}
await browser.close();
server.close();
