// Drives headless Chromium through the DevTools protocol over --remote-debugging-pipe (no npm
// package, no WebSocket) to test the interactive comparison of a `godrays run` report
// (src/report/viewer.c): real mouse clicks, key presses, slider clicks and wheel events, then
// what the canvas shows. Used by tests/cli/test_report_viewer.sh, which passes:
//   node report_viewer_cdp.js BROWSER URL OUTDIR DUMPDATA_FILE
// DUMPDATA_FILE: `oiiotool --dumpdata reference.exr` (the independent reading of the linear
// truth that the page's decoded floats are checked against). Prints "ok: ..." / "FAIL: ..."
// lines; exit status 0 only if every check holds. Screenshots go to OUTDIR/viewer_*.png.
'use strict';
const { spawn } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

const [browser, url, outdir, dumpfile] = process.argv.slice(2);
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'grv-'));
const chrome = spawn(browser, ['--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    '--user-data-dir=' + profile, '--remote-debugging-pipe', '--hide-scrollbars', 'about:blank'],
    { stdio: ['ignore', 'ignore', 'ignore', 'pipe', 'pipe'] });
const toChrome = chrome.stdio[3], fromChrome = chrome.stdio[4];
let nextId = 1, pending = new Map(), inbox = '', sessionId = null;
const console_msgs = [];
fromChrome.on('data', (chunk) => {
    inbox += chunk.toString('utf8');
    let z;
    while ((z = inbox.indexOf('\0')) >= 0) {
        const msg = JSON.parse(inbox.slice(0, z));
        inbox = inbox.slice(z + 1);
        if (msg.id && pending.has(msg.id)) {
            const p = pending.get(msg.id);
            pending.delete(msg.id);
            if (msg.error) p.reject(new Error(p.method + ': ' + msg.error.message)); else p.resolve(msg.result);
        } else if (msg.method === 'Runtime.consoleAPICalled') {
            console_msgs.push('console.' + msg.params.type + ': ' + msg.params.args.map((a) => a.value).join(' '));
        } else if (msg.method === 'Runtime.exceptionThrown') {
            console_msgs.push('exception: ' + JSON.stringify(msg.params.exceptionDetails.exception ||
                msg.params.exceptionDetails.text));
        } else if (msg.method === 'Log.entryAdded') {
            console_msgs.push('log ' + msg.params.entry.level + ': ' + msg.params.entry.text);
        }
    }
});
function send(method, params, session) {
    const id = nextId++;
    const m = { id, method, params: params || {} };
    if (session !== null) m.sessionId = session === undefined ? sessionId : session;
    toChrome.write(JSON.stringify(m) + '\0');
    return new Promise((resolve, reject) => pending.set(id, { resolve, reject, method }));
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function js(expr) {
    const r = await send('Runtime.evaluate', { expression: expr, returnByValue: true });
    if (r.exceptionDetails) throw new Error('evaluate ' + expr.slice(0, 60) + ': ' + r.exceptionDetails.text);
    return r.result.value;
}
let failed = 0;
function ck(desc, cond) {
    console.log((cond ? 'ok: ' : 'FAIL: ') + desc);
    if (!cond) failed = 1;
}
async function mouse(type, x, y, extra) {
    await send('Input.dispatchMouseEvent', Object.assign({ type, x, y, button: 'left', clickCount: 1 }, extra || {}));
}
async function click(x, y) {
    await mouse('mouseMoved', x, y, { button: 'none' });
    await mouse('mousePressed', x, y, { buttons: 1 });
    await mouse('mouseReleased', x, y, { buttons: 0 });
    await sleep(50);
}
async function key(k, code, vk) {
    await send('Input.dispatchKeyEvent', { type: 'keyDown', key: k, code, windowsVirtualKeyCode: vk, text: k });
    await send('Input.dispatchKeyEvent', { type: 'keyUp', key: k, code, windowsVirtualKeyCode: vk });
    await sleep(50);
}
// The canvas as the page holds it: a hash, mean code value, and per-column means.
// (read from a copy made for reading, so that the page's canvas sees no readback)
const CANVAS = `(function(){var c=document.getElementById('grv-canvas'),w=c.width,h=c.height,
 k=document.createElement('canvas');k.width=w;k.height=h;var g=k.getContext('2d',{willReadFrequently:true});
 g.drawImage(c,0,0);var d=g.getImageData(0,0,w,h).data,s=0,hs=0,col=new Array(w).fill(0);
 for(var i=0;i<d.length;i+=4){var v=d[i]+d[i+1]+d[i+2];s+=v;col[(i/4)%w]+=v;hs=(hs*31+d[i]+7*d[i+1]+13*d[i+2])>>>0;}
 return {hash:hs,mean:s/(w*h*3),col:col.map(function(x){return x/(h*3);}),
 state:document.getElementById('grv').getAttribute('data-state'),w:w,h:h};})()`;
async function rectOf(id) {
    return js(`(function(){var r=document.getElementById('${id}').getBoundingClientRect();
      return {x:r.left,y:r.top,w:r.width,h:r.height};})()`);
}
async function shot(name, r) {
    const s = await send('Page.captureScreenshot', { format: 'png',
        clip: { x: r.x + r.sx, y: r.y + r.sy, width: r.w, height: r.h, scale: 1 } });
    const buf = Buffer.from(s.data, 'base64');
    fs.writeFileSync(path.join(outdir, 'viewer_' + name + '.png'), buf);
    return buf;
}

async function main() {
    const { targetId } = await send('Target.createTarget', { url: 'about:blank' }, null);
    sessionId = (await send('Target.attachToTarget', { targetId, flatten: true }, null)).sessionId;
    await send('Runtime.enable');
    await send('Log.enable');
    await send('Page.enable');
    await send('Emulation.setDeviceMetricsOverride', { width: 1300, height: 1000, deviceScaleFactor: 1, mobile: false });
    await send('Page.navigate', { url });
    let ready = null;
    for (let i = 0; i < 600 && ready !== '1'; i++) {
        await sleep(100);
        ready = await js(`(function(){var g=document.getElementById('grv');return g&&g.getAttribute('data-ready');})()`)
            .catch(() => null);
    }
    ck('the comparison decoded its images (data-ready)', ready === '1');
    if (ready !== '1') return;
    await js(`document.getElementById('grv').scrollIntoView()`);
    await sleep(100);
    const scroll = await js(`({sx: window.scrollX, sy: window.scrollY})`);
    const cr = Object.assign(await rectOf('grv-canvas'), scroll);

    // 0. the decoded linear truth against oiiotool's reading of reference.exr (RGBE: each
    //    channel within 2^-8 of the pixel's largest channel, relative)
    const dump = fs.readFileSync(dumpfile, 'utf8').split('\n');
    const step = await js('GRV_DATA.step');
    let worst = 0, n = 0;
    if (step === 1) {
        for (const line of dump) {
            const m = /Pixel \((\d+), (\d+)\): (.*)/.exec(line);
            if (!m || (+m[1] * 7 + +m[2] * 3) % 11) continue; // a spread-out subset
            const want = m[3].trim().split(/\s+/).slice(0, 3).map(Number);
            const got = await js(`grViewer.pixel('truth', ${m[1]}, ${m[2]})`);
            const mx = Math.max(...want);
            for (let c = 0; c < 3; c++) worst = Math.max(worst, mx > 0 ? Math.abs(got[c] - want[c]) / mx : got[c]);
            n++;
        }
    }
    ck(`decoded truth matches oiiotool --dumpdata (${n} pixels, worst ${worst.toExponential(2)} of the max ` +
       'channel, bound 2^-8)', n > 100 && worst <= 1 / 256);

    const s0 = await js(CANVAS);
    const p0 = await shot('truth', cr);
    ck('starts on the ground truth (' + s0.state + ')', s0.state === 'flip:truth:0');
    ck('the canvas is not blank (mean code ' + s0.mean.toFixed(1) + ')', s0.mean > 2);

    // 1. a click on the image flips to the technique
    await click(cr.x + cr.w / 2, cr.y + cr.h / 2);
    const s1 = await js(CANVAS);
    const p1 = await shot('technique', cr);
    ck('a click flips to the technique (' + s1.state + ')', s1.state === 'flip:test:0');
    ck('the click changed the canvas', s1.hash !== s0.hash);
    ck('the click changed the screenshot', !p1.equals(p0));
    // 2. the space bar flips back: the same pixels as before
    await key(' ', 'Space', 32);
    const s2 = await js(CANVAS);
    ck('space flips back to the truth (' + s2.state + ')', s2.state === 'flip:truth:0' && s2.hash === s0.hash);

    // 3. the exposure slider: a click at 80 % of its track moves it up: brighter
    const er = await rectOf('grv-ev');
    await click(er.x + 0.8 * er.w, er.y + er.h / 2);
    const ev = await js(`+document.getElementById('grv-ev').value`);
    const s3 = await js(CANVAS);
    const p3 = await shot('exposure', cr);
    ck(`the exposure slider moved (${ev / 10} EV)`, ev > 20);
    ck(`higher exposure is brighter (mean ${s0.mean.toFixed(1)} -> ${s3.mean.toFixed(1)})`, s3.mean > s0.mean + 1);
    ck('the slider changed the screenshot', !p3.equals(p0));
    await key('0', 'Digit0', 48); // (zoom reset only; the exposure stays)
    await click((await rectOf('grv-reset')).x + 5, (await rectOf('grv-reset')).y + 5);
    const s3b = await js(CANVAS);
    ck('reset view restores 0 EV (the same pixels as at first)', s3b.hash === s0.hash);

    // 4. the wipe slider at 30 %: truth left of the line, technique right of it
    await click(cr.x + cr.w / 2, cr.y + cr.h / 2); // technique, for its columns
    const st = await js(CANVAS);
    await key(' ', 'Space', 32);
    const wr = await rectOf('grv-wipe');
    await click(wr.x + 0.3 * wr.w, wr.y + wr.h / 2);
    const wv = await js(`+document.getElementById('grv-wipe').value`);
    const s4 = await js(CANVAS);
    const p4 = await shot('wipe', cr);
    const xline = Math.round(s4.w * wv / 1000);
    let lok = true, rok = true;
    for (let x = 0; x < s4.w; x++) {
        if (Math.abs(x - xline) <= 2 * s4.w / 160 + 2) continue; // the line and the pixel it cuts
        if (x < xline && Math.abs(s4.col[x] - s0.col[x]) > 1e-9) lok = false;
        if (x > xline && Math.abs(s4.col[x] - st.col[x]) > 1e-9) rok = false;
    }
    ck(`the wipe slider switched to wipe (${s4.state}, at ${wv / 10} %)`, s4.state === 'wipe:0' && wv > 200 && wv < 400);
    ck('left of the wipe line: the truth\'s columns', lok);
    ck('right of the wipe line: the technique\'s columns', rok);
    ck('the wipe changed the screenshot', !p4.equals(p0) && !p4.equals(p1));

    // 5. zoom (wheel) and pan (drag); a drag does not flip
    await key(' ', 'Space', 32);
    const s5a = await js(CANVAS);
    await mouse('mouseWheel', cr.x + cr.w / 2, cr.y + cr.h / 2, { button: 'none', deltaX: 0, deltaY: -240 });
    await sleep(50);
    const z = await js('grViewer.state.zoom');
    const s5 = await js(CANVAS);
    const p5 = await shot('zoom', cr);
    ck(`the wheel zooms in (x${z})`, z > 1.2 && s5.hash !== s5a.hash && !p5.equals(p0));
    const px0 = await js('grViewer.state.px');
    await mouse('mousePressed', cr.x + cr.w / 2, cr.y + cr.h / 2, { buttons: 1 });
    for (let i = 1; i <= 5; i++) await mouse('mouseMoved', cr.x + cr.w / 2 + 10 * i, cr.y + cr.h / 2, { buttons: 1 });
    await mouse('mouseReleased', cr.x + cr.w / 2 + 50, cr.y + cr.h / 2, { buttons: 0 });
    await sleep(50);
    const s6 = await js(CANVAS);
    const px1 = await js('grViewer.state.px');
    ck(`a drag pans (${px0.toFixed(1)} -> ${px1.toFixed(1)}) without flipping (${s6.state})`,
       Math.abs(px1 - px0 - 50) < 1 && s6.state === s5.state && s6.hash !== s5.hash);

    // 6. the FLIP map (key m), then the second technique (key 2) if there is one
    await key('0', 'Digit0', 48);
    await key('m', 'KeyM', 77);
    const s7 = await js(CANVAS);
    await shot('flipmap', cr);
    ck('m shows the FLIP map (' + s7.state + ')', s7.state === 'flipmap:0' && s7.hash !== s0.hash);
    const nt = await js('GRV_DATA.tech.length');
    if (nt > 1) {
        await key('2', 'Digit2', 50);
        const s8 = await js(CANVAS);
        ck('2 selects the second technique\'s FLIP map', s8.state === 'flipmap:1' && s8.hash !== s7.hash);
    }
    await sleep(200);
    ck('no console message, no exception' + (console_msgs.length ? ': ' + console_msgs.join(' | ') : ''),
       console_msgs.length === 0);
}

const guard = setTimeout(() => { console.log('FAIL: timed out'); process.exit(1); }, 240000);
main().catch((e) => { console.log('FAIL: ' + e.message); failed = 1; }).finally(async () => {
    clearTimeout(guard);
    try { await Promise.race([send('Browser.close', {}, null), sleep(2000)]); } catch (e) { /* closing */ }
    chrome.kill();
    await Promise.race([new Promise((r) => chrome.on('exit', r)), sleep(3000)]);
    try { fs.rmSync(profile, { recursive: true, force: true }); } catch (e) { /* a file Chromium still wrote */ }
    process.exit(failed);
});
