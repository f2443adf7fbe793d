/* Interactive charts (chart.h). */
#include "report/chart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compare/fit.h"
#include "image/png.h"
#include "report/report.h"

/* Tableau's 10 colours (matplotlib's default cycle), then 10 darker ones. */
static const char *const palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                                      "#7f7f7f", "#bcbd22", "#17becf", "#0b3c5d", "#a64d00", "#17601a", "#7a1414",
                                      "#4b2c6b", "#4a2c24", "#8a2f6f", "#3a3a3a", "#6b6b0f", "#0b6570"};

const char *gr_chart_library_path(void)
{
    static char env_path[4096];
    const char *env = getenv("GODRAYS_CHARTJS");
    if (env && *env) {
        snprintf(env_path, sizeof env_path, "%s", env);
        return env_path;
    }
    static const char *const debian[] = {"/usr/share/javascript/chart.js/chart.min.js",
                                         "/usr/share/javascript/chart.js/chart.js"};
    for (size_t i = 0; i < sizeof debian / sizeof *debian; i++) {
        FILE *f = fopen(debian[i], "rb");
        if (f) {
            fclose(f);
            return debian[i];
        }
    }
    return NULL;
}

/* The whole file at path, NUL-terminated; NULL if unreadable or empty. */
static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = NULL;
    size_t len = 0, cap = 0, got;
    char chunk[65536];
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (len + got + 1 > cap) {
            cap = 2 * (len + got + 1);
            char *nb = realloc(buf, cap);
            if (!nb) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = nb;
        }
        memcpy(buf + len, chunk, got);
        len += got;
    }
    fclose(f);
    if (buf) buf[len] = '\0';
    return buf;
}

/* s as a JSON string, safe inside <script>: '<', '>' and '&' as \u escapes, so that no text
 * can close the script element. */
static void json_str(gr_strbuf *b, const char *s)
{
    gr_sb_puts(b, "\"");
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\') gr_sb_printf(b, "\\%c", *p);
        else if (*p == '\n') gr_sb_puts(b, "\\n");
        else if (*p < 0x20 || *p == '<' || *p == '>' || *p == '&') gr_sb_printf(b, "\\u%04x", *p);
        else gr_sb_printf(b, "%c", *p);
    }
    gr_sb_puts(b, "\"");
}

/* The library, with any "</script" (none in 3.9.1) written "<\/script", which JavaScript reads
 * the same inside a string or a regular expression. */
static void put_library(gr_strbuf *b, const char *lib)
{
    gr_sb_puts(b, "<script>\n");
    for (const char *p = lib; *p;) {
        const char *q = strstr(p, "</script");
        if (!q) {
            gr_sb_puts(b, p);
            break;
        }
        gr_sb_printf(b, "%.*s<\\/", (int)(q - p), p);
        p = q + 2;
    }
    gr_sb_puts(b, "\n</script>\n");
}

/* The page's script: grChart(D) draws chart D.id or leaves the fallback with the reason. */
static const char *const chart_js =
    "function grChart(D){var st=document.getElementById(D.id+'-status');"
    "function esc(s){return String(s).replace(/[&<>\"]/g,function(c){return{'&':'&amp;','<':'&lt;','>':'&gt;','\"':'&quot;'}[c];});}"
    "try{if(typeof Chart==='undefined')throw new Error('Chart.js did not load');"
    "var box=document.getElementById(D.id+'-box'),cv=document.getElementById(D.id+'-canvas'),"
    "tip=document.getElementById(D.id+'-tip'),band=document.getElementById(D.id+'-band');"
    "box.style.display='block';"
    "var ds=D.series.map(function(s){return{label:s.name,data:[],borderColor:s.color,"
    "backgroundColor:s.hollow?'rgba(255,255,255,0.6)':s.color,pointRadius:5,pointHoverRadius:8,"
    "borderWidth:s.hollow?2:1,showLine:false};}),where=[];"
    "D.points.forEach(function(p,k){var d=ds[p.s];where[k]=[p.s,d.data.length];d.data.push({x:p.x,y:p.y,k:k});});"
    /* each visible family's front, joined in time order, clipped to the plot area */
    "var front={id:'grfront',afterDatasetsDraw:function(c){var x=c.ctx,a=c.chartArea;x.save();x.beginPath();"
    "x.rect(a.left,a.top,a.right-a.left,a.bottom-a.top);x.clip();"
    "c.data.datasets.forEach(function(d,i){if(!c.isDatasetVisible(i))return;var m=c.getDatasetMeta(i),e=[];"
    "d.data.forEach(function(v,j){if(D.points[v.k].f)e.push(m.data[j]);});if(e.length<2)return;"
    "e.sort(function(u,w){return u.x-w.x;});x.strokeStyle=d.borderColor;x.lineWidth=1.5;"
    "x.setLineDash(D.series[i].hollow?[6,4]:[]);x.beginPath();"
    "e.forEach(function(p,n){if(n)x.lineTo(p.x,p.y);else x.moveTo(p.x,p.y);});x.stroke();});x.restore();}};"
    /* the ready mark the browser test reads: the points drawn */
    "var ready={id:'grready',afterRender:function(c){var n=0;c.data.datasets.forEach(function(d,i){"
    "if(!c.isDatasetVisible(i))return;c.getDatasetMeta(i).data.forEach(function(e){if(!e.skip&&isFinite(e.x)&&isFinite(e.y))n++;});});"
    "st.setAttribute('data-ready','1');st.setAttribute('data-points',String(n));"
    "st.textContent=n+' points drawn. Hover a point for its settings, errors and thumbnail; click a legend entry to hide '+"
    "'or show its family; drag a box to zoom.';}};"
    "function external(ctx){var t=ctx.tooltip;if(!t||t.opacity===0||!t.dataPoints||!t.dataPoints.length){tip.style.display='none';return;}"
    "var p=D.points[t.dataPoints[0].raw.k],h='<b>'+esc(p.t)+'</b>';p.d.forEach(function(l){h+='<br>'+esc(l);});"
    "if(p.img)h+='<br><img src=\"'+esc(p.img)+'\" alt=\"thumbnail\">';tip.innerHTML=h;tip.style.display='block';"
    "var w=cv.clientWidth;tip.style.left=(t.caretX>w/2?Math.max(0,t.caretX-tip.offsetWidth-14):t.caretX+14)+'px';"
    "tip.style.top=Math.max(0,t.caretY-tip.offsetHeight/2)+'px';}"
    "var ch=new Chart(cv,{type:'scatter',data:{datasets:ds},plugins:[front,ready],options:{animation:false,"
    "responsive:true,maintainAspectRatio:false,plugins:{title:{display:true,text:D.title},"
    "tooltip:{enabled:false,external:external},legend:{position:'right'}},"
    "scales:{x:{type:'logarithmic',title:{display:true,text:D.x}},"
    "y:{type:D.logy?'logarithmic':'linear',title:{display:true,text:D.y}}}}});"
    "window.grCharts=window.grCharts||{};window.grCharts[D.id]=ch;"
    "var fb=document.getElementById(D.id+'-fallback');if(fb)fb.style.display='none';"
    /* zoom: drag a box; reset; log/linear error axis */
    "var z=null;cv.addEventListener('mousedown',function(e){z={x:e.offsetX,y:e.offsetY};});"
    "cv.addEventListener('mousemove',function(e){if(!z)return;band.style.display='block';"
    "band.style.left=Math.min(z.x,e.offsetX)+'px';band.style.top=Math.min(z.y,e.offsetY)+'px';"
    "band.style.width=Math.abs(e.offsetX-z.x)+'px';band.style.height=Math.abs(e.offsetY-z.y)+'px';});"
    "window.addEventListener('mouseup',function(e){if(!z)return;var a=z;z=null;band.style.display='none';"
    "var r=cv.getBoundingClientRect(),ex=e.clientX-r.left,ey=e.clientY-r.top;"
    "if(Math.abs(ex-a.x)<5||Math.abs(ey-a.y)<5)return;var X=ch.scales.x,Y=ch.scales.y,o=ch.options.scales;"
    "o.x.min=Math.min(X.getValueForPixel(a.x),X.getValueForPixel(ex));o.x.max=Math.max(X.getValueForPixel(a.x),X.getValueForPixel(ex));"
    "o.y.min=Math.min(Y.getValueForPixel(a.y),Y.getValueForPixel(ey));o.y.max=Math.max(Y.getValueForPixel(a.y),Y.getValueForPixel(ey));"
    "ch.update();});"
    "document.getElementById(D.id+'-reset').addEventListener('click',function(){var o=ch.options.scales;"
    "delete o.x.min;delete o.x.max;delete o.y.min;delete o.y.max;ch.update();});"
    "document.getElementById(D.id+'-logy').addEventListener('click',function(){var o=ch.options.scales.y;"
    "o.type=o.type==='logarithmic'?'linear':'logarithmic';delete o.min;delete o.max;ch.update();});"
    /* table rows: hovering one highlights its point and shows its tooltip */
    "function rows(){document.querySelectorAll('[data-gr-chart=\"'+D.id+'\"]').forEach(function(row){var k=+row.getAttribute('data-gr-point');"
    "row.addEventListener('mouseenter',function(){var w=where[k];if(!w)return;var e=ch.getDatasetMeta(w[0]).data[w[1]];"
    "var act=[{datasetIndex:w[0],index:w[1]}];ch.setActiveElements(act);ch.tooltip.setActiveElements(act,{x:e.x,y:e.y});ch.update();});"
    "row.addEventListener('mouseleave',function(){ch.setActiveElements([]);ch.tooltip.setActiveElements([],{x:0,y:0});ch.update();});});}"
    /* the rows come after the chart in the page */
    "if(document.readyState==='loading')document.addEventListener('DOMContentLoaded',rows);else rows();"
    "}catch(e){st.textContent='The interactive chart failed ('+e.message+'): the PNG chart is shown instead.';"
    "var fb2=document.getElementById(D.id+'-fallback');if(fb2)fb2.style.display='block';"
    "var b2=document.getElementById(D.id+'-box');if(b2)b2.style.display='none';}}\n";

static const char *const chart_css =
    "<style>.gr-chart-box{position:relative;height:560px;display:none;border:1px solid #ccc;background:#fff}"
    ".gr-chart-tip{position:absolute;display:none;pointer-events:none;background:rgba(255,255,255,.96);"
    "border:1px solid #888;padding:.4em .6em;font-size:12px;max-width:420px;z-index:2;box-shadow:2px 2px 6px rgba(0,0,0,.25)}"
    ".gr-chart-tip img{width:192px;margin-top:.3em;border:1px solid #ccc;image-rendering:pixelated}"
    ".gr-chart-band{position:absolute;display:none;pointer-events:none;border:1px dashed #333;background:rgba(80,120,200,.12)}"
    ".gr-chart-status{font-size:90%;color:#555}tr[data-gr-chart]:hover{background:#fff3c4}</style>\n";

/* The data object grChart reads. */
static void chart_data(gr_strbuf *b, const gr_chart *c)
{
    gr_sb_printf(b, "{\"id\":");
    json_str(b, c->id);
    gr_sb_puts(b, ",\"title\":[");
    json_str(b, c->title ? c->title : "");
    if (c->subtitle) {
        gr_sb_puts(b, ",");
        json_str(b, c->subtitle);
    }
    gr_sb_puts(b, "],\"x\":");
    json_str(b, c->x_label ? c->x_label : "");
    gr_sb_puts(b, ",\"y\":");
    json_str(b, c->y_label ? c->y_label : "");
    gr_sb_printf(b, ",\"logy\":%d,\"series\":[", c->log_y ? 1 : 0);
    const int n_pal = (int)(sizeof palette / sizeof *palette);
    for (int s = 0; s < c->n_series; s++) {
        gr_sb_puts(b, s ? ",{\"name\":" : "{\"name\":");
        json_str(b, c->series[s].name);
        const int ci = c->series[s].color >= 0 ? c->series[s].color % n_pal : 0;
        gr_sb_printf(b, ",\"color\":\"%s\",\"hollow\":%d}", palette[ci], c->series[s].hollow ? 1 : 0);
    }
    gr_sb_puts(b, "],\"points\":[");
    int first = 1;
    for (int k = 0; k < c->n_points; k++) {
        const gr_chart_point *p = &c->points[k];
        /* a point the log axis cannot place still holds its index (rows refer to it): y null */
        const int ok = p->series >= 0 && p->series < c->n_series && isfinite(p->x) && p->x > 0 && isfinite(p->y) &&
                       (!c->log_y || p->y > 0);
        gr_sb_puts(b, first ? "" : ",");
        first = 0;
        if (!ok) {
            gr_sb_printf(b, "{\"s\":%d,\"x\":null,\"y\":null,\"f\":0,\"t\":\"\",\"d\":[],\"img\":\"\"}",
                         p->series >= 0 && p->series < c->n_series ? p->series : 0);
            continue;
        }
        gr_sb_printf(b, "{\"s\":%d,\"x\":%.9g,\"y\":%.9g,\"f\":%d,\"t\":", p->series, p->x, p->y, p->on_front ? 1 : 0);
        json_str(b, p->title);
        gr_sb_puts(b, ",\"d\":[");
        for (const char *l = p->lines; *l;) {
            const size_t n = strcspn(l, "\n");
            char line[1024];
            snprintf(line, sizeof line, "%.*s", (int)n, l);
            if (l != p->lines) gr_sb_puts(b, ",");
            json_str(b, line);
            l += n + (l[n] == '\n');
        }
        gr_sb_puts(b, "],\"img\":");
        json_str(b, p->thumb);
        gr_sb_puts(b, "}");
    }
    gr_sb_puts(b, "]}");
}

int gr_chart_html(gr_strbuf *b, const gr_chart *c, char *why, size_t n_why)
{
    const char *path = gr_chart_library_path();
    char *lib = path ? read_all(path) : NULL;
    if (!lib)
        snprintf(why, n_why, "the interactive chart needs Chart.js, and %s could not be read (install Debian's "
                 "libjs-chart.js: scripts/setup.sh; or set GODRAYS_CHARTJS to the file)",
                 path ? path : "/usr/share/javascript/chart.js/chart.min.js");
    else if (n_why > 0)
        why[0] = '\0';
    gr_sb_puts(b, chart_css);
    gr_sb_puts(b, "<div class=\"gr-chart\">");
    if (lib) {
        gr_sb_printf(b, "<p><button type=\"button\" id=\"%s-reset\">reset zoom</button> "
                       "<button type=\"button\" id=\"%s-logy\">error axis: log / linear</button> ", c->id, c->id);
        gr_sb_printf(b, "<span class=\"gr-chart-status\" id=\"%s-status\">", c->id);
        gr_sb_puts(b, "The interactive chart needs JavaScript: the PNG chart is shown instead.</span></p>\n");
        gr_sb_printf(b, "<div class=\"gr-chart-box\" id=\"%s-box\"><canvas id=\"%s-canvas\"></canvas>", c->id, c->id);
        gr_sb_printf(b, "<div class=\"gr-chart-band\" id=\"%s-band\"></div>", c->id);
        gr_sb_printf(b, "<div class=\"gr-chart-tip\" id=\"%s-tip\"></div></div>\n", c->id);
    } else {
        gr_sb_puts(b, "<p class=\"gr-chart-status\">");
        gr_sb_html(b, why);
        gr_sb_puts(b, ": the PNG chart is shown instead.</p>\n");
    }
    gr_sb_printf(b, "<div id=\"%s-fallback\">", c->id);
    if (c->png) {
        gr_sb_puts(b, "<img src=\"");
        gr_sb_html(b, c->png);
        gr_sb_puts(b, "\" alt=\"");
        gr_sb_html(b, c->title ? c->title : "chart");
        gr_sb_puts(b, "\">");
    } else {
        gr_sb_puts(b, "<p>(no PNG chart either: PLplot missing)</p>");
    }
    gr_sb_puts(b, "</div></div>\n");
    if (!lib) return 0;
    put_library(b, lib);
    free(lib);
    gr_sb_puts(b, "<script>\n");
    gr_sb_puts(b, chart_js);
    gr_sb_puts(b, "grChart(");
    chart_data(b, c);
    gr_sb_puts(b, ");\n</script>\n");
    return 1;
}

void gr_chart_row_attrs(gr_strbuf *b, const char *id, int k)
{
    gr_sb_puts(b, " data-gr-chart=\"");
    gr_sb_html(b, id);
    gr_sb_printf(b, "\" data-gr-point=\"%d\"", k);
}

void gr_chart_thumb_name(int k, char *buf, size_t n) { snprintf(buf, n, "thumbs/p%d.png", k); }

gr_status gr_chart_write_thumb(const char *dir, const char *name, const gr_image *truth, const gr_image *img,
                               gr_error *err)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/thumbs", dir);
    gr_status st = gr_report_make_dir(path, err);
    if (st != GR_OK) return st;
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path)
        return gr_fail(err, GR_E_USAGE, "%s: directory name too long", dir);
    static const int rgb[3] = {0, 1, 2};
    double a[3] = {1, 1, 1};
    /* the fit of the report's T.png: the technique at the truth's level, at the truth's exposure */
    if (truth && gr_fit_scales(truth, img, NULL, rgb, rgb, GR_FIT_SCALE, a) != 3) a[0] = 1;
    const double exposure = truth ? gr_report_exposure(truth, 1.0, 0.99, 0.8) : gr_report_exposure(img, 1.0, 0.99, 0.8);
    return gr_png_write_preview(path, img, rgb, exposure * a[0], err);
}
