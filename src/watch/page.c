/* The page of `godrays watch` (watch.h): static HTML whose script polls /state.json every
 * 0.5 s and, when the render id changes, reloads the images (their URLs carry the id) and
 * fills the numbers, or shows the error and the compiler's log one line per diagnostic. No
 * external resource: it works offline. */
#include "watch/watch.h"

static const char page[] =
    "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>godrays watch</title>\n"
    "<style>body{font:14px sans-serif;margin:1em;background:#fafafa}figure{display:inline-block;margin:0 1em 1em 0}"
    "figure img{image-rendering:pixelated;width:320px;border:1px solid #ccc;background:#000}"
    "figcaption{font-size:12px;color:#555}#log{background:#fee;border:1px solid #c66;padding:.5em;"
    "white-space:pre-wrap;font:13px monospace}.bad{color:#a00}.ok{color:#060}"
    "table{border-collapse:collapse}td,th{padding:2px 8px;text-align:right;border-bottom:1px solid #ddd}"
    "td:first-child,th:first-child{text-align:left}</style></head>\n<body>\n"
    "<h1>godrays watch: <span id=\"technique\">...</span></h1>\n"
    "<p>render <span id=\"render-id\">0</span> (<span id=\"changed\"></span>, <span id=\"when\"></span>): "
    "<b id=\"status\">waiting</b> <span id=\"note\"></span></p>\n"
    "<p id=\"verdict-line\">verdict <b id=\"verdict\">-</b>, scale fit <span id=\"scale\">-</span>, "
    "render <span id=\"wall\">-</span> ms</p>\n"
    "<pre id=\"log\" hidden></pre>\n"
    "<div><figure><img id=\"img-test\" alt=\"render\"><figcaption>render (the truth's exposure)</figcaption></figure>"
    "<figure><img id=\"img-truth\" alt=\"truth\"><figcaption>ground truth</figcaption></figure>"
    "<figure><img id=\"img-diff\" alt=\"difference\"><figcaption>|dY| after the scale fit</figcaption></figure>"
    "<figure><img id=\"img-flip\" alt=\"FLIP\"><figcaption>HDR-FLIP</figcaption></figure></div>\n"
    "<table id=\"metrics\"><thead><tr><th>metric</th><th>as rendered</th><th>after the fit</th></tr></thead>"
    "<tbody></tbody></table>\n"
    "<script>\n"
    "var last=-1;function $(i){return document.getElementById(i);}\n"
    "function num(v){return v===null||v===undefined?'-':Number(v).toPrecision(4);}\n"
    "function show(s){$('technique').textContent=s.technique||'?';$('render-id').textContent=s.id;"
    "$('changed').textContent=s.changed;$('when').textContent=s.time;$('note').textContent=s.note||'';"
    "var st=$('status');st.className=s.ok?'ok':'bad';st.textContent=s.ok?'ok':s.stage+' error';"
    "var log=$('log');log.hidden=s.ok;log.textContent=s.ok?'':s.message.split('\\n').join('\\n');"
    "$('img-truth').src='img/truth.png';"
    "if(s.ok){['test','diff','flip'].forEach(function(k){$('img-'+k).src='img/'+k+'.png?id='+s.id;});"
    "$('verdict').textContent=num(s.verdict);$('scale').textContent=num(s.scale);"
    "$('wall').textContent=num(s.wall_ms);var tb=$('metrics').tBodies[0];tb.innerHTML='';"
    "s.metrics.forEach(function(m){var r=tb.insertRow();r.insertCell().textContent=m.label;"
    "r.insertCell().textContent=num(m.raw);r.insertCell().textContent=num(m.fit);});}}\n"
    "function poll(){fetch('state.json',{cache:'no-store'}).then(function(r){return r.json();})"
    ".then(function(s){if(s.id!==undefined&&s.id!==last){last=s.id;show(s);}}).catch(function(){})"
    ".then(function(){setTimeout(poll,500);});}\n"
    "poll();\n</script>\n</body></html>\n";

const char *gr_watch_page(void) { return page; }
