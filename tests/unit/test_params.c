/* Settings descriptor tables and their generic accessors: lookups, defaults written at the
 * right offsets, range checks at and around every bound, integer/bool/enum rules, every
 * default inside its range, descriptors covering their structs, and exact number printing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene/params.h"
#include "scene/settings.h"
#include "realtime/shafts.h"

static const gr_param_table *tables[2] = {&gr_reference_param_table, &gr_shafts_param_table};

static size_t field_size(const gr_param *p)
{
    switch (p->type) {
    case GR_PT_DOUBLE: return sizeof(double);
    case GR_PT_INT:
    case GR_PT_BOOL:
    case GR_PT_ENUM: return sizeof(int);
    case GR_PT_U64: return sizeof(unsigned long long);
    case GR_PT_RGB: return 3 * sizeof(double);
    }
    return 0;
}

static void test_find(void)
{
    const gr_param *k = gr_param_find(&gr_shafts_param_table, "K");
    CHECK(k != NULL && k->type == GR_PT_DOUBLE && !strcmp(k->name, "K"));
    CHECK(gr_param_find(&gr_shafts_param_table, "k") == NULL); /* case-sensitive */
    CHECK(gr_param_find(&gr_shafts_param_table, "nope") == NULL);
    CHECK(gr_param_find(&gr_shafts_param_table, NULL) == NULL);
    CHECK(gr_param_find(NULL, "K") == NULL);
    const gr_param *spp = gr_param_find(&gr_reference_param_table, "spp");
    CHECK(spp && spp->type == GR_PT_INT && spp->offset == offsetof(gr_reference_settings, spp));
    CHECK(gr_param_find(&gr_reference_param_table, "K") == NULL); /* tables are separate */
    CHECK(!strcmp(gr_reference_param_table.section, "reference"));
    CHECK(!strcmp(gr_shafts_param_table.section, "shafts"));
    /* names are unique within a table and every entry has a doc line */
    for (int t = 0; t < 2; t++)
        for (size_t i = 0; i < tables[t]->count; i++) {
            const gr_param *p = &tables[t]->params[i];
            CHECK_MSG(p->name && p->name[0] && p->doc && p->doc[0] && p->unit, "%s entry %zu", tables[t]->section, i);
            CHECK_MSG(gr_param_find(tables[t], p->name) == p, "%s.%s duplicated", tables[t]->section, p->name);
        }
}

static void test_defaults(void)
{
    gr_reference_settings r;
    gr_shafts_settings s;
    memset(&r, 0xAB, sizeof r);
    memset(&s, 0xAB, sizeof s);
    gr_param_defaults(&gr_reference_param_table, &r);
    gr_param_defaults(&gr_shafts_param_table, &s);
    /* values from the project brief that are not tuning knobs */
    CHECK(r.seed == 1ull && r.threads == 0 && r.target_error == 0.0 && r.transmittance_cutoff == 1e-4);
    CHECK(s.caps == 1 && s.target_format == GR_TARGET_RGBA8);
    CHECK(isnan(s.extinction[0]) && isnan(s.extinction[1]) && isnan(s.extinction[2]));
    CHECK(s.g == 0.5); /* the seed's g (issue 12), no longer the medium's */
    /* every field equals its descriptor's default, read back through the typed struct */
    CHECK(r.spp == (int)gr_param_find(&gr_reference_param_table, "spp")->def);
    CHECK(s.N == (int)gr_param_find(&gr_shafts_param_table, "N")->def);
    CHECK(s.K == gr_param_find(&gr_shafts_param_table, "K")->def);
    CHECK(s.intensity[2] == gr_param_find(&gr_shafts_param_table, "intensity")->def);
    CHECK(s.shadow_bias == gr_param_find(&gr_shafts_param_table, "shadow_bias")->def);
    for (int t = 0; t < 2; t++) {
        void *st = t ? (void *)&s : (void *)&r;
        for (size_t i = 0; i < tables[t]->count; i++) {
            const gr_param *p = &tables[t]->params[i];
            int nch = p->type == GR_PT_RGB ? 3 : 1;
            for (int c = 0; c < nch; c++) {
                double v = gr_param_get_number(p, st, c);
                if (p->flags & GR_PF_FROM_SCENE) CHECK_MSG(isnan(v), "%s.%s should be NaN", tables[t]->section, p->name);
                else CHECK_MSG(v == p->def, "%s.%s = %g, def %g", tables[t]->section, p->name, v, p->def);
            }
        }
        /* defaults validate (FROM_SCENE left unresolved is allowed only when asked) */
        gr_error err;
        CHECK_OK(gr_param_validate(tables[t], st, 1, &err), err);
        if (t == 1) CHECK(gr_param_validate(tables[t], st, 0, &err) == GR_E_INPUT);
    }
}

/* every default lies in its range (FROM_SCENE ones are resolved from the scene) */
static void test_defaults_in_range(void)
{
    gr_error err;
    for (int t = 0; t < 2; t++)
        for (size_t i = 0; i < tables[t]->count; i++) {
            const gr_param *p = &tables[t]->params[i];
            if (p->flags & GR_PF_FROM_SCENE) {
                CHECK_MSG(isnan(p->def) && p->scene_source, "%s.%s: FROM_SCENE needs NaN def and a source",
                          tables[t]->section, p->name);
                continue;
            }
            gr_status st = gr_param_check(tables[t], p, p->def, -1, &err);
            CHECK_MSG(st == GR_OK, "%s.%s default: %s", tables[t]->section, p->name, err.msg);
            CHECK_MSG(p->min <= p->max, "%s.%s: empty range", tables[t]->section, p->name);
        }
}

static void test_ranges(void)
{
    gr_error err;
    gr_shafts_settings s;
    gr_reference_settings r;
    gr_param_defaults(&gr_shafts_param_table, &s);
    gr_param_defaults(&gr_reference_param_table, &r);
    /* every bound of every numeric entry: inclusive accepts, exclusive rejects, beyond rejects */
    for (int t = 0; t < 2; t++) {
        void *st = t ? (void *)&s : (void *)&r;
        for (size_t i = 0; i < tables[t]->count; i++) {
            const gr_param *p = &tables[t]->params[i];
            if (p->type == GR_PT_BOOL || p->type == GR_PT_ENUM) continue;
            double step = (p->type == GR_PT_DOUBLE || p->type == GR_PT_RGB) ? fmax(fabs(p->min), 1.0) * 1e-9 : 1.0;
            if (isfinite(p->min)) {
                gr_status lo = gr_param_set_number(tables[t], st, p->name, -1, p->min, &err);
                CHECK_MSG((lo == GR_OK) == !(p->flags & GR_PF_MIN_EXCL), "%s.%s at min", tables[t]->section, p->name);
                CHECK_MSG(gr_param_set_number(tables[t], st, p->name, -1, p->min - step, &err) == GR_E_INPUT,
                          "%s.%s below min", tables[t]->section, p->name);
                CHECK_MSG(strstr(err.msg, tables[t]->section) == err.msg && strstr(err.msg, p->name) &&
                              strstr(err.msg, "got"), "message: %s", err.msg);
            }
            if (isfinite(p->max)) {
                double stepm = (p->type == GR_PT_DOUBLE || p->type == GR_PT_RGB) ? fmax(fabs(p->max), 1.0) * 1e-9 : 1.0;
                gr_status hi = gr_param_set_number(tables[t], st, p->name, -1, p->max, &err);
                CHECK_MSG((hi == GR_OK) == !(p->flags & GR_PF_MAX_EXCL), "%s.%s at max", tables[t]->section, p->name);
                CHECK_MSG(gr_param_set_number(tables[t], st, p->name, -1, p->max + stepm, &err) == GR_E_INPUT,
                          "%s.%s above max", tables[t]->section, p->name);
            }
            CHECK(gr_param_set_number(tables[t], st, p->name, -1, NAN, &err) == GR_E_INPUT);
            CHECK(gr_param_set_number(tables[t], st, p->name, -1, INFINITY, &err) == GR_E_INPUT);
        }
    }
    /* a failed set leaves the value alone */
    gr_param_defaults(&gr_shafts_param_table, &s);
    double k0 = s.K;
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "K", -1, -5.0, &err) == GR_E_INPUT);
    CHECK(s.K == k0);
    CHECK(strstr(err.msg, "shafts.K: must be in (0, ") != NULL && strstr(err.msg, "got -5") != NULL);
    CHECK_OK(gr_param_set_number(&gr_shafts_param_table, &s, "K", -1, 0.7, &err), err);
    CHECK(s.K == 0.7 && gr_param_get_number(gr_param_find(&gr_shafts_param_table, "K"), &s, 0) == 0.7);
    /* integers */
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "N", -1, 12.5, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "shafts.N: must be an integer") != NULL);
    CHECK_OK(gr_param_set_number(&gr_shafts_param_table, &s, "N", -1, 12.0, &err), err);
    CHECK(s.N == 12);
    /* u64: integer-valued, 0 .. 2^53 - 1 */
    CHECK_OK(gr_param_set_number(&gr_reference_param_table, &r, "seed", -1, 9007199254740991.0, &err), err);
    CHECK(r.seed == 9007199254740991ull);
    CHECK(gr_param_set_number(&gr_reference_param_table, &r, "seed", -1, 9007199254740992.0, &err) == GR_E_INPUT);
    CHECK(gr_param_set_number(&gr_reference_param_table, &r, "seed", -1, -1.0, &err) == GR_E_INPUT);
    /* booleans */
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "caps", -1, 0.5, &err) == GR_E_INPUT);
    CHECK_OK(gr_param_set_number(&gr_shafts_param_table, &s, "caps", -1, 0.0, &err), err);
    CHECK(s.caps == 0);
    /* RGB: one channel or all */
    CHECK_OK(gr_param_set_number(&gr_shafts_param_table, &s, "intensity", -1, 2.0, &err), err);
    CHECK_OK(gr_param_set_number(&gr_shafts_param_table, &s, "intensity", 1, 3.0, &err), err);
    CHECK(s.intensity[0] == 2.0 && s.intensity[1] == 3.0 && s.intensity[2] == 2.0);
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "intensity", 2, -1.0, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "shafts.intensity[2]") != NULL);
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "intensity", 3, 1.0, &err) == GR_E_INPUT);
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "K", 0, 1.0, &err) == GR_E_INPUT);
    /* unknown keys */
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "Kx", -1, 1.0, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "shafts.Kx: unknown key") != NULL);
    /* validate catches a value written behind the table's back */
    gr_param_defaults(&gr_reference_param_table, &r);
    r.steps = 0;
    CHECK(gr_param_validate(&gr_reference_param_table, &r, 1, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "reference.steps") != NULL);
}

static void test_enum(void)
{
    const gr_param *p = gr_param_find(&gr_shafts_param_table, "target_format");
    gr_error err;
    gr_shafts_settings s;
    gr_param_defaults(&gr_shafts_param_table, &s);
    CHECK(p && p->type == GR_PT_ENUM);
    CHECK(gr_param_enum_index(p, "rgba8") == GR_TARGET_RGBA8);
    CHECK(gr_param_enum_index(p, "rgba16f") == GR_TARGET_RGBA16F);
    CHECK(gr_param_enum_index(p, "RGBA8") == -1);
    CHECK(gr_param_enum_index(p, "") == -1);
    CHECK(!strcmp(gr_param_enum_name(p, 1), "rgba16f"));
    CHECK(gr_param_enum_name(p, 2) == NULL && gr_param_enum_name(p, -1) == NULL);
    CHECK(gr_param_enum_index(gr_param_find(&gr_shafts_param_table, "K"), "rgba8") == -1);
    CHECK_OK(gr_param_set_enum(&gr_shafts_param_table, &s, "target_format", "rgba16f", &err), err);
    CHECK(s.target_format == GR_TARGET_RGBA16F);
    CHECK(gr_param_set_enum(&gr_shafts_param_table, &s, "target_format", "rgb8", &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "shafts.target_format: unknown value, expected one of rgba8, rgba16f, got \"rgb8\"") != NULL);
    CHECK(s.target_format == GR_TARGET_RGBA16F);
    CHECK(gr_param_set_enum(&gr_shafts_param_table, &s, "K", "rgba8", &err) == GR_E_INPUT);
    CHECK(gr_param_set_number(&gr_shafts_param_table, &s, "target_format", -1, 2.0, &err) == GR_E_INPUT);
    CHECK_OK(gr_param_set_number(&gr_shafts_param_table, &s, "target_format", -1, 0.0, &err), err);
}

/* The descriptors cover their structs: no gap between described fields is large enough
 * to hold an undescribed field of the following field's alignment, and none overlap. */
static void test_coverage(void)
{
    const size_t sizes[2] = {sizeof(gr_reference_settings), sizeof(gr_shafts_settings)};
    for (int t = 0; t < 2; t++) {
        size_t n = tables[t]->count;
        const gr_param **order = malloc(n * sizeof *order);
        for (size_t i = 0; i < n; i++) order[i] = &tables[t]->params[i];
        for (size_t i = 1; i < n; i++)
            for (size_t j = i; j > 0 && order[j - 1]->offset > order[j]->offset; j--) {
                const gr_param *x = order[j];
                order[j] = order[j - 1];
                order[j - 1] = x;
            }
        size_t end = 0;
        for (size_t i = 0; i < n; i++) {
            size_t align = order[i]->type == GR_PT_INT || order[i]->type == GR_PT_BOOL || order[i]->type == GR_PT_ENUM
                               ? sizeof(int) : sizeof(double);
            CHECK_MSG(order[i]->offset >= end, "%s.%s overlaps", tables[t]->section, order[i]->name);
            CHECK_MSG(order[i]->offset - end < align, "%s: undescribed field before %s", tables[t]->section, order[i]->name);
            end = order[i]->offset + field_size(order[i]);
        }
        CHECK_MSG(sizes[t] - end < sizeof(double), "%s: undescribed field at the end", tables[t]->section);
        free(order);
    }
}

static void test_text(void)
{
    char buf[64];
    CHECK(!strcmp(gr_format_double(0.1, buf, sizeof buf), "0.1"));
    CHECK(!strcmp(gr_format_double(1e-3, buf, sizeof buf), "0.001"));
    CHECK(!strcmp(gr_format_double(-0.0, buf, sizeof buf), "-0"));
    CHECK(!strcmp(gr_format_double(INFINITY, buf, sizeof buf), "inf"));
    CHECK(!strcmp(gr_format_double(NAN, buf, sizeof buf), "nan"));
    /* round trip of pseudo-random doubles over many magnitudes (LCG, fixed seed) */
    unsigned long long x = 12345;
    for (int i = 0; i < 20000; i++) {
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        double m = (double)(x >> 11) / 9007199254740992.0;
        double v = ldexp(m, (int)(x % 200) - 100) * ((x >> 7) & 1 ? -1.0 : 1.0);
        gr_format_double(v, buf, sizeof buf);
        CHECK_MSG(strtod(buf, NULL) == v, "%.17g printed as %s", v, buf);
    }
    const gr_param *p = gr_param_find(&gr_shafts_param_table, "g");
    CHECK(!strcmp(gr_param_range_text(p, buf, sizeof buf), "(-1, 1)"));
    p = gr_param_find(&gr_shafts_param_table, "caps");
    CHECK(!strcmp(gr_param_range_text(p, buf, sizeof buf), "true or false"));
    gr_param q = {.name = "q", .type = GR_PT_DOUBLE, .min = 0, .max = INFINITY, .flags = GR_PF_MIN_EXCL};
    CHECK(!strcmp(gr_param_range_text(&q, buf, sizeof buf), "> 0"));
}

int main(void)
{
    test_find();
    test_defaults();
    test_defaults_in_range();
    test_ranges();
    test_enum();
    test_coverage();
    test_text();
    CHECK_DONE();
}
