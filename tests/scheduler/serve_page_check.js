// The page of `gravsweep serve` in a real browser (Debian's chromium driven by playwright-core,
// which downloads no browser of its own): it loads, its done count changes while a worker runs,
// a click on a drop draws the drop's trace on the canvas, the Froude collapse is drawn, the model's
// verdict appears once enough drops have finished, and no script error occurs. Writes a
// screenshot and prints one JSON line of what it saw (times in ms).
//
//   node serve_page_check.js URL SCREENSHOT READY_FILE DROP_JOB_ID   # the test (test_serve_browser.cpp)
//   node serve_page_check.js URL SCREENSHOT --load                    # load time only (docs/serve.md)
//
// READY_FILE is written once the page shows its first counts: the test starts the worker then.
// Exit code 0: every check held; 1: one failed (the message says which).
"use strict";
const fs = require("fs");
const { chromium } = require("playwright-core");

const [url, shot, third, dropId] = process.argv.slice(2);
const loadOnly = third === "--load";

function fail(why) {
  console.error("serve_page_check: " + why);
  process.exit(1);
}

async function inkedPixels(page, id) {
  return page.evaluate((id) => {
    const c = document.getElementById(id);
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) ++n;
    return n;
  }, id);
}

async function main() {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox"],
  });
  const page = await browser.newPage({ viewport: { width: 1280, height: 1000 } });
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => /^\d+$/.test(document.getElementById("done-total").textContent));
  const statusMs = Date.now() - t0;
  await page.waitForSelector("#results thead tr", { timeout: 120000 });
  const loadMs = Date.now() - t0;
  const first = Number(await page.textContent("#done-total"));
  if (loadOnly) {
    await page.screenshot({ path: shot, fullPage: true });
    console.log(JSON.stringify({ statusMs, loadMs, done: first, errors }));
    await browser.close();
    if (errors.length) fail("script errors: " + errors.join("; "));
    return;
  }
  fs.writeFileSync(third, String(first));
  await page.waitForFunction((n) => Number(document.getElementById("done-total").textContent) > n, first,
                             { timeout: 600000, polling: 200 });
  const later = Number(await page.textContent("#done-total"));
  const row = `#results tbody tr[data-job="${dropId}"]`;
  await page.waitForSelector(row, { timeout: 600000 });
  await page.click(row);
  await page.waitForSelector("#trace-canvas[data-drawn]", { timeout: 60000 });
  const traceInk = await inkedPixels(page, "trace-canvas");
  if (traceInk < 500) fail(`the trace canvas is nearly blank (${traceInk} pixels drawn)`);
  // The drop's Fig. 2 and Fig. 1, drawn by the server, shown as images.
  for (const fig of ["fig2", "fig1"]) {
    await page.waitForSelector(`#${fig}-img[data-loaded="${dropId}"]`, { timeout: 120000 })
      .catch(async () => fail(`${fig} of the drop never loaded: ` + await page.textContent("#figs-info")));
    const width = await page.evaluate((id) => document.getElementById(id).naturalWidth, `${fig}-img`);
    if (!(width > 400)) fail(`${fig} of the drop is ${width} pixels wide`);
  }
  // The figure: zstop against impact speed (the drops' metrics).
  await page.selectOption("#fig-y", "zstop_m").catch(() => {});
  await page.waitForSelector("#figure-canvas[data-drawn]", { timeout: 60000 });
  const figureInk = await inkedPixels(page, "figure-canvas");
  // The Froude collapse of the finished drops, and the model's verdict once enough have finished.
  await page.waitForSelector("#collapse-canvas[data-drawn]", { timeout: 120000 });
  const collapseInk = await inkedPixels(page, "collapse-canvas");
  if (collapseInk < 500) fail(`the collapse canvas is nearly blank (${collapseInk} pixels drawn)`);
  const collapseDrops = Number(await page.getAttribute("#collapse-canvas", "data-drawn"));
  await page.waitForSelector('#rank-verdict[data-state="ready"]', { timeout: 600000 });
  const verdict = await page.textContent("#rank-verdict");
  const rankRows = await page.locator("#rank tbody tr").count();
  const levelRows = await page.locator("#levels tbody tr").count();
  await page.screenshot({ path: shot, fullPage: true });
  console.log(JSON.stringify({ statusMs, loadMs, first, later, traceInk, figureInk, collapseInk, collapseDrops,
                               verdict, rankRows, levelRows, errors }));
  await browser.close();
  if (errors.length) fail("script errors: " + errors.join("; "));
}

main().catch((e) => fail(e.stack || String(e)));
