/* The user's own technique: a folder with a JSON manifest (manifest.json) and GLSL files,
 * turned into a gr_technique_class like the built-in ones (docs/techniques.md).
 *
 * Loading (no GL): the manifest is parsed and validated, every shader file it names is read,
 * and its settings become a gr_param_table (section = the manifest's name), so the scene
 * loader, --set NAME.KEY=V, sweeps and tuning work on them unchanged. Errors: GR_E_INPUT
 * with "DIR/manifest.json: JSON.PATH: reason" (one line).
 *
 * Creating (current GL context): each pass's shaders are compiled behind a generated prelude
 * that declares the harness's uniforms and textures, the settings' uniforms (u_set_KEY) and
 * the pass's input textures (t_NAME). A compile or link failure is GR_E_GL with the file
 * name and the GLSL log (line numbers are the file's own: the prelude ends in #line 1).
 *
 * Rendering: a generic multi-pass executor (targets, blend states, clears, draws, inputs,
 * one GPU timer per pass), then the output target's RGB is read back. A NaN/Inf in the
 * output, an output pass that drew no fragment, or an all-zero output is an error
 * (GR_E_RUNTIME), never a silently black image; "allow_black": true in the manifest
 * accepts the last case. */
#ifndef GR_USERTECH_H
#define GR_USERTECH_H

#include "common/status.h"
#include "realtime/technique.h"
#include "realtime/usertech_manifest.h" /* GR_USERTECH_MANIFEST */

/* Parses and validates DIR/manifest.json and reads its shader files; *out is a new class
 * (name, description, params, callbacks) owned by the caller: gr_usertech_free. */
gr_status gr_usertech_load(const char *dir, gr_technique_class **out, gr_error *err);
void gr_usertech_free(gr_technique_class *cls); /* accepts NULL */

/* The generated GLSL prelude of pass `pass` (0-based) and stage ("vertex" or "fragment"):
 * what a user shader sees before its first line. malloc'd; NULL on a bad index or no memory.
 * For docs and tests (`godrays techniques --json` does not print it). */
char *gr_usertech_prelude(const gr_technique_class *cls, int pass, const char *stage);

/* 1 if cls was made by gr_usertech_load. */
int gr_usertech_is_user(const gr_technique_class *cls);

#endif
