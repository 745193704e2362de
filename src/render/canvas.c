/* The off-screen GL context (OSMesa on llvmpipe: no X, no GPU) and the canvas primitives. Edges
 * are anti-aliased analytically in the fragment shaders (coverage from the distance of the pixel
 * centre to the shape), so the result is exact, needs no multisampling and is deterministic. */
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <ft2build.h>
#include FT_FREETYPE_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/render_internal.h"

#define FONT_PATH "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"

typedef struct disk_inst {
    float x, y, r, edge;
    rgba8 c;
} disk_inst;

typedef struct seg_inst {
    float x0, y0, x1, y1, hw, round;
    rgba8 c;
} seg_inst;

enum { PENDING_NONE, PENDING_DISKS, PENDING_SEGS };

struct render_context {
    OSMesaContext osm;
    unsigned char osm_buf[RENDER_MIN_SIZE * RENDER_MIN_SIZE * 4]; /* keeps the context current */
    GLuint fbo, color_rb;  /* drawing goes here: OSMesa's own buffer does not follow size changes
                            * reliably, a renderbuffer of the image's size does */
    int fb_w, fb_h;
    unsigned char *buf;    /* glReadPixels target */
    size_t buf_size;
    int w, h;
    GLuint vao_disk, vao_seg, vao_text, corner_vbo, disk_vbo, seg_vbo, text_tex, pixels_tex;
    GLuint prog_disk, prog_seg, prog_text, prog_pixels;
    GLint u_disk_view, u_seg_view, u_text_view, u_text_box, u_text_color, u_text_tex;
    GLint u_pixels_view, u_pixels_box, u_pixels_tex;
    disk_inst *disks;
    size_t ndisks, cap_disks;
    seg_inst *segs;
    size_t nsegs, cap_segs;
    int pending;
    int oom;
    FT_Library ft;
    FT_Face face;
    unsigned char *glyphs; /* text bitmap scratch */
    size_t glyphs_size;
};

/* ---- shaders ------------------------------------------------------------------------------- */
static const char *DISK_VS =
    "#version 330 core\n"
    "layout(location = 0) in vec2 corner;\n"
    "layout(location = 1) in vec4 disk;\n" /* centre (window px), radius, rim width */
    "layout(location = 2) in vec4 color;\n"
    "uniform vec2 view;\n"
    "flat out vec4 v_disk;\n"
    "flat out vec4 v_color;\n"
    "void main() {\n"
    "  vec2 p = disk.xy + corner * (disk.z + 1.0);\n"
    "  gl_Position = vec4(p / view * 2.0 - 1.0, 0.0, 1.0);\n"
    "  v_disk = disk; v_color = color;\n"
    "}\n";

static const char *DISK_FS =
    "#version 330 core\n"
    "flat in vec4 v_disk;\n"
    "flat in vec4 v_color;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "  float d = length(gl_FragCoord.xy - v_disk.xy);\n"
    "  float cov = clamp(v_disk.z - d + 0.5, 0.0, 1.0);\n"
    "  if (cov <= 0.0) discard;\n"
    "  vec3 c = v_color.rgb;\n"
    "  if (v_disk.w > 0.0)\n"
    "    c = mix(c, c * 0.5, clamp(d - (v_disk.z - v_disk.w) + 0.5, 0.0, 1.0));\n"
    "  else if (v_disk.w < 0.0) {\n" /* a sphere: Lambert + Blinn-Phong, light upper left */
    "    vec2 q = (gl_FragCoord.xy - v_disk.xy) / v_disk.z;\n"
    "    float q2 = min(dot(q, q), 1.0);\n"
    "    vec3 n = vec3(q, sqrt(1.0 - q2));\n"
    "    vec3 l = normalize(vec3(-0.45, 0.55, 0.70));\n"
    "    vec3 h = normalize(l + vec3(0.0, 0.0, 1.0));\n"
    "    float diff = max(dot(n, l), 0.0);\n"
    "    float spec = pow(max(dot(n, h), 0.0), 40.0);\n"
    "    c = min(c * (0.28 + 0.72 * diff) + vec3(0.35 * spec), vec3(1.0));\n"
    "  }\n"
    "  frag = vec4(c, v_color.a * cov);\n"
    "}\n";

static const char *SEG_VS =
    "#version 330 core\n"
    "layout(location = 0) in vec2 corner;\n"
    "layout(location = 1) in vec4 seg;\n"   /* end points (window px) */
    "layout(location = 2) in vec2 par;\n"   /* half width, round caps */
    "layout(location = 3) in vec4 color;\n"
    "uniform vec2 view;\n"
    "flat out vec4 v_seg;\n"
    "flat out vec2 v_par;\n"
    "flat out vec4 v_color;\n"
    "void main() {\n"
    "  vec2 ab = seg.zw - seg.xy;\n"
    "  float len = length(ab);\n"
    "  vec2 dir = len > 0.0 ? ab / len : vec2(1.0, 0.0);\n"
    "  vec2 nrm = vec2(-dir.y, dir.x);\n"
    "  float e = max(par.x, 0.5) + 1.0;\n"
    "  vec2 p = (corner.x < 0.0 ? seg.xy - dir * e : seg.zw + dir * e) + nrm * corner.y * e;\n"
    "  gl_Position = vec4(p / view * 2.0 - 1.0, 0.0, 1.0);\n"
    "  v_seg = seg; v_par = par; v_color = color;\n"
    "}\n";

static const char *SEG_FS =
    "#version 330 core\n"
    "flat in vec4 v_seg;\n"
    "flat in vec2 v_par;\n"
    "flat in vec4 v_color;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "  vec2 ab = v_seg.zw - v_seg.xy;\n"
    "  float len = length(ab);\n"
    "  vec2 dir = len > 0.0 ? ab / len : vec2(1.0, 0.0);\n"
    "  vec2 q = gl_FragCoord.xy - v_seg.xy;\n"
    "  float t = dot(q, dir), s = abs(dot(q, vec2(-dir.y, dir.x)));\n"
    "  float hw = max(v_par.x, 0.5);\n"
    "  float cov;\n"
    "  if (v_par.y > 0.5)\n"
    "    cov = clamp(hw - length(vec2(max(max(-t, t - len), 0.0), s)) + 0.5, 0.0, 1.0);\n"
    "  else\n"
    "    cov = clamp(hw - s + 0.5, 0.0, 1.0) * clamp(min(t, len - t) + 0.5, 0.0, 1.0);\n"
    "  if (cov <= 0.0) discard;\n"
    "  frag = vec4(v_color.rgb, v_color.a * cov * (v_par.x / hw));\n"
    "}\n";

static const char *TEXT_VS =
    "#version 330 core\n"
    "layout(location = 0) in vec2 corner;\n"
    "uniform vec2 view;\n"
    "uniform vec4 box;\n" /* bottom-left window pixel, size */
    "void main() {\n"
    "  vec2 p = box.xy + (corner * 0.5 + 0.5) * box.zw;\n"
    "  gl_Position = vec4(p / view * 2.0 - 1.0, 0.0, 1.0);\n"
    "}\n";

static const char *TEXT_FS =
    "#version 330 core\n"
    "uniform vec4 box;\n"
    "uniform vec4 color;\n"
    "uniform sampler2D tex;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(floor(gl_FragCoord.xy - box.xy));\n"
    "  float cov = texelFetch(tex, ivec2(p.x, int(box.w) - 1 - p.y), 0).r;\n"
    "  if (cov <= 0.0) discard;\n"
    "  frag = vec4(color.rgb, color.a * cov);\n"
    "}\n";

/* Pixel blocks: the box's texels one to one (top row first), alpha 0 left out. */
static const char *PIXELS_FS =
    "#version 330 core\n"
    "uniform vec4 box;\n"
    "uniform sampler2D tex;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(floor(gl_FragCoord.xy - box.xy));\n"
    "  vec4 c = texelFetch(tex, ivec2(p.x, int(box.w) - 1 - p.y), 0);\n"
    "  if (c.a <= 0.0) discard;\n"
    "  frag = c;\n"
    "}\n";

static GLuint compile(GLenum type, const char *src, core_error *err)
{
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        core_fail(err, CORE_ERR_STATE, "render: shader does not compile: %s", log);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

static GLuint program(const char *vs, const char *fs, core_error *err)
{
    GLuint v = compile(GL_VERTEX_SHADER, vs, err);
    if (!v)
        return 0;
    GLuint f = compile(GL_FRAGMENT_SHADER, fs, err);
    if (!f) {
        glDeleteShader(v);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[400];
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        core_fail(err, CORE_ERR_STATE, "render: shaders do not link: %s", log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

static void instance_attrib(GLuint loc, GLint size, GLenum type, GLboolean norm, GLsizei stride,
                            size_t offset)
{
    glEnableVertexAttribArray(loc);
    glVertexAttribPointer(loc, size, type, norm, stride, (const void *)offset);
    glVertexAttribDivisor(loc, 1);
}

static void corner_attrib(GLuint vbo)
{
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
}

static core_status setup_gl(render_context *rc, core_error *err)
{
    if (!(rc->prog_disk = program(DISK_VS, DISK_FS, err)) ||
        !(rc->prog_seg = program(SEG_VS, SEG_FS, err)) ||
        !(rc->prog_text = program(TEXT_VS, TEXT_FS, err)) ||
        !(rc->prog_pixels = program(TEXT_VS, PIXELS_FS, err)))
        return err ? err->status : CORE_ERR_STATE;
    rc->u_disk_view = glGetUniformLocation(rc->prog_disk, "view");
    rc->u_seg_view = glGetUniformLocation(rc->prog_seg, "view");
    rc->u_text_view = glGetUniformLocation(rc->prog_text, "view");
    rc->u_text_box = glGetUniformLocation(rc->prog_text, "box");
    rc->u_text_color = glGetUniformLocation(rc->prog_text, "color");
    rc->u_text_tex = glGetUniformLocation(rc->prog_text, "tex");
    rc->u_pixels_view = glGetUniformLocation(rc->prog_pixels, "view");
    rc->u_pixels_box = glGetUniformLocation(rc->prog_pixels, "box");
    rc->u_pixels_tex = glGetUniformLocation(rc->prog_pixels, "tex");

    static const float corners[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
    glGenBuffers(1, &rc->corner_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, rc->corner_vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
    glGenBuffers(1, &rc->disk_vbo);
    glGenBuffers(1, &rc->seg_vbo);

    glGenVertexArrays(1, &rc->vao_disk);
    glBindVertexArray(rc->vao_disk);
    corner_attrib(rc->corner_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, rc->disk_vbo);
    instance_attrib(1, 4, GL_FLOAT, GL_FALSE, sizeof(disk_inst), offsetof(disk_inst, x));
    instance_attrib(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(disk_inst), offsetof(disk_inst, c));

    glGenVertexArrays(1, &rc->vao_seg);
    glBindVertexArray(rc->vao_seg);
    corner_attrib(rc->corner_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, rc->seg_vbo);
    instance_attrib(1, 4, GL_FLOAT, GL_FALSE, sizeof(seg_inst), offsetof(seg_inst, x0));
    instance_attrib(2, 2, GL_FLOAT, GL_FALSE, sizeof(seg_inst), offsetof(seg_inst, hw));
    instance_attrib(3, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(seg_inst), offsetof(seg_inst, c));

    glGenVertexArrays(1, &rc->vao_text);
    glBindVertexArray(rc->vao_text);
    corner_attrib(rc->corner_vbo);
    glGenTextures(1, &rc->text_tex);
    glBindTexture(GL_TEXTURE_2D, rc->text_tex);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenTextures(1, &rc->pixels_tex); /* complete without mipmaps, as texelFetch needs */
    glBindTexture(GL_TEXTURE_2D, rc->pixels_tex);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindVertexArray(0);
    if (glGetError() != GL_NO_ERROR)
        return core_fail(err, CORE_ERR_STATE, "render: OpenGL setup failed");
    return CORE_OK;
}

static core_status load_font(render_context *rc, core_error *err)
{
    const char *path = getenv("GRAINLAB_FONT");
    if (!path || !*path)
        path = FONT_PATH;
    if (access(path, R_OK) != 0)
        return core_fail(err, CORE_ERR_IO,
                         "render: font %s not found: apt-get install fonts-dejavu-core (or set "
                         "GRAINLAB_FONT to a TrueType file)", path);
    if (FT_Init_FreeType(&rc->ft))
        return core_fail(err, CORE_ERR_STATE, "render: FreeType does not start");
    if (FT_New_Face(rc->ft, path, 0, &rc->face))
        return core_fail(err, CORE_ERR_IO, "render: cannot read the font %s", path);
    return CORE_OK;
}

core_status render_context_create(render_context **out, core_error *err)
{
    *out = NULL;
    render_context *rc = calloc(1, sizeof *rc);
    if (!rc)
        return core_fail(err, CORE_ERR_NOMEM, "render: out of memory");
    core_status st = load_font(rc, err);
    if (st != CORE_OK) {
        render_context_destroy(rc);
        return st;
    }
    static const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0,
                                  OSMESA_STENCIL_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                                  OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3,
                                  0};
    rc->osm = OSMesaCreateContextAttribs(attribs, NULL);
    if (!rc->osm) {
        render_context_destroy(rc);
        return core_fail(err, CORE_ERR_STATE,
                         "render: no OpenGL 3.3 off-screen context (OSMesa from libosmesa6 is "
                         "needed: apt-get install libosmesa6)");
    }
    if (!OSMesaMakeCurrent(rc->osm, rc->osm_buf, GL_UNSIGNED_BYTE, RENDER_MIN_SIZE,
                           RENDER_MIN_SIZE)) {
        render_context_destroy(rc);
        return core_fail(err, CORE_ERR_STATE, "render: cannot make the OpenGL context current");
    }
    st = setup_gl(rc, err);
    if (st != CORE_OK) {
        render_context_destroy(rc);
        return st;
    }
    *out = rc;
    return CORE_OK;
}

void render_context_destroy(render_context *rc)
{
    if (!rc)
        return;
    if (rc->osm)
        OSMesaDestroyContext(rc->osm);
    if (rc->face)
        FT_Done_Face(rc->face);
    if (rc->ft)
        FT_Done_FreeType(rc->ft);
    free(rc->buf);
    free(rc->disks);
    free(rc->segs);
    free(rc->glyphs);
    free(rc);
}

/* ---- canvas -------------------------------------------------------------------------------- */
static void flush(render_context *rc)
{
    if (rc->pending == PENDING_DISKS && rc->ndisks) {
        glUseProgram(rc->prog_disk);
        glUniform2f(rc->u_disk_view, (float)rc->w, (float)rc->h);
        glBindVertexArray(rc->vao_disk);
        glBindBuffer(GL_ARRAY_BUFFER, rc->disk_vbo);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(rc->ndisks * sizeof(disk_inst)), rc->disks,
                     GL_STREAM_DRAW);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)rc->ndisks);
    } else if (rc->pending == PENDING_SEGS && rc->nsegs) {
        glUseProgram(rc->prog_seg);
        glUniform2f(rc->u_seg_view, (float)rc->w, (float)rc->h);
        glBindVertexArray(rc->vao_seg);
        glBindBuffer(GL_ARRAY_BUFFER, rc->seg_vbo);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(rc->nsegs * sizeof(seg_inst)), rc->segs,
                     GL_STREAM_DRAW);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)rc->nsegs);
    }
    rc->ndisks = rc->nsegs = 0;
    rc->pending = PENDING_NONE;
}

core_status canvas_begin(render_context *rc, int w, int h, core_error *err)
{
    if (w < 1 || h < 1 || w > RENDER_MAX_SIZE || h > RENDER_MAX_SIZE)
        return core_fail(err, CORE_ERR_ARG, "image size %d x %d outside [%d, %d] pixels", w, h,
                         RENDER_MIN_SIZE, RENDER_MAX_SIZE);
    size_t need = (size_t)w * (size_t)h * 4;
    if (need > rc->buf_size) {
        unsigned char *b = malloc(need);
        if (!b)
            return core_fail(err, CORE_ERR_NOMEM, "render: no memory for a %d x %d image", w, h);
        free(rc->buf);
        rc->buf = b;
        rc->buf_size = need;
    }
    if (!OSMesaMakeCurrent(rc->osm, rc->osm_buf, GL_UNSIGNED_BYTE, RENDER_MIN_SIZE,
                           RENDER_MIN_SIZE))
        return core_fail(err, CORE_ERR_STATE, "render: cannot make the OpenGL context current");
    while (glGetError() != GL_NO_ERROR)
        ;
    if (w != rc->fb_w || h != rc->fb_h) {
        if (rc->fbo) {
            glDeleteFramebuffers(1, &rc->fbo);
            glDeleteRenderbuffers(1, &rc->color_rb);
        }
        glGenFramebuffers(1, &rc->fbo);
        glGenRenderbuffers(1, &rc->color_rb);
        glBindRenderbuffer(GL_RENDERBUFFER, rc->color_rb);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
        glBindFramebuffer(GL_FRAMEBUFFER, rc->fbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                  rc->color_rb);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE ||
            glGetError() != GL_NO_ERROR) {
            glDeleteFramebuffers(1, &rc->fbo);
            glDeleteRenderbuffers(1, &rc->color_rb);
            rc->fbo = rc->color_rb = 0;
            rc->fb_w = rc->fb_h = 0;
            return core_fail(err, CORE_ERR_NOMEM, "render: cannot draw a %d x %d image", w, h);
        }
        rc->fb_w = w;
        rc->fb_h = h;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, rc->fbo);
    rc->w = w;
    rc->h = h;
    rc->ndisks = rc->nsegs = 0;
    rc->pending = PENDING_NONE;
    rc->oom = 0;
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glClearColor(1, 1, 1, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    return CORE_OK;
}

core_status canvas_end(render_context *rc, render_image *out, core_error *err)
{
    flush(rc);
    out->width = out->height = 0;
    out->rgba = NULL;
    if (rc->oom)
        return core_fail(err, CORE_ERR_NOMEM, "render: out of memory while drawing");
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, rc->w, rc->h, GL_RGBA, GL_UNSIGNED_BYTE, rc->buf);
    if (glGetError() != GL_NO_ERROR)
        return core_fail(err, CORE_ERR_STATE, "render: OpenGL reported an error while drawing");
    size_t row = (size_t)rc->w * 4;
    out->rgba = malloc(row * rc->h);
    if (!out->rgba)
        return core_fail(err, CORE_ERR_NOMEM, "render: no memory for a %d x %d image", rc->w,
                         rc->h);
    for (int y = 0; y < rc->h; y++) { /* GL rows go bottom-up, images top-down */
        unsigned char *dst = out->rgba + row * y;
        memcpy(dst, rc->buf + row * (rc->h - 1 - y), row);
        for (int x = 0; x < rc->w; x++)
            dst[4 * x + 3] = 255;
    }
    out->width = rc->w;
    out->height = rc->h;
    return CORE_OK;
}

static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap * 2 : 1024;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, c * size);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

void canvas_disk(render_context *rc, double x, double y, double r, double edge, rgba8 c)
{
    if (!(r > 0) || x + r + 1 < 0 || y + r + 1 < 0 || x - r - 1 > rc->w || y - r - 1 > rc->h)
        return;
    if (rc->pending != PENDING_DISKS)
        flush(rc);
    rc->pending = PENDING_DISKS;
    if (!grow((void **)&rc->disks, &rc->cap_disks, rc->ndisks + 1, sizeof(disk_inst))) {
        rc->oom = 1;
        return;
    }
    if (r < 0.7) { /* below a pixel the analytic coverage overestimates: keep the area */
        c.a = (unsigned char)lround(c.a * (r * r) / (0.7 * 0.7));
        r = 0.7;
    }
    disk_inst *d = &rc->disks[rc->ndisks++];
    d->x = (float)x;
    d->y = (float)(rc->h - y);
    d->r = (float)r;
    d->edge = (float)edge;
    d->c = c;
}

void canvas_segment(render_context *rc, double x0, double y0, double x1, double y1, double w,
                    int round, rgba8 c)
{
    if (!(w > 0))
        return;
    if (rc->pending != PENDING_SEGS)
        flush(rc);
    rc->pending = PENDING_SEGS;
    if (!grow((void **)&rc->segs, &rc->cap_segs, rc->nsegs + 1, sizeof(seg_inst))) {
        rc->oom = 1;
        return;
    }
    seg_inst *s = &rc->segs[rc->nsegs++];
    s->x0 = (float)x0;
    s->y0 = (float)(rc->h - y0);
    s->x1 = (float)x1;
    s->y1 = (float)(rc->h - y1);
    s->hw = (float)(0.5 * w);
    s->round = round ? 1.0f : 0.0f;
    s->c = c;
}

void canvas_rect(render_context *rc, double x0, double y0, double x1, double y1, rgba8 c)
{
    if (x1 < x0) {
        double t = x0;
        x0 = x1;
        x1 = t;
    }
    if (y1 < y0) {
        double t = y0;
        y0 = y1;
        y1 = t;
    }
    canvas_segment(rc, x0, 0.5 * (y0 + y1), x1, 0.5 * (y0 + y1), y1 - y0, 0, c);
}

void canvas_arrow(render_context *rc, double x0, double y0, double x1, double y1, double dx,
                  double dy, double w, double hl, rgba8 c)
{
    const double cs = 0.906, sn = 0.423; /* cos and sin of 25 degrees */
    canvas_segment(rc, x0, y0, x1, y1, w, 1, c);
    canvas_segment(rc, x1, y1, x1 - hl * (cs * dx - sn * dy), y1 - hl * (sn * dx + cs * dy), w, 1,
                   c);
    canvas_segment(rc, x1, y1, x1 - hl * (cs * dx + sn * dy), y1 - hl * (-sn * dx + cs * dy), w,
                   1, c);
}

void canvas_pixels(render_context *rc, int x, int y, int w, int h, const unsigned char *rgba)
{
    if (w < 1 || h < 1)
        return;
    flush(rc);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, rc->pixels_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    glUseProgram(rc->prog_pixels);
    glUniform2f(rc->u_pixels_view, (float)rc->w, (float)rc->h);
    glUniform4f(rc->u_pixels_box, (float)x, (float)(rc->h - y - h), (float)w, (float)h);
    glUniform1i(rc->u_pixels_tex, 0);
    glBindVertexArray(rc->vao_text);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

/* ---- text ---------------------------------------------------------------------------------- */
/* Next code point of a UTF-8 string (invalid bytes read as U+FFFD). */
static unsigned long utf8_next(const char **s)
{
    const unsigned char *p = (const unsigned char *)*s;
    unsigned long cp;
    int extra;
    if (p[0] < 0x80) {
        cp = p[0];
        extra = 0;
    } else if ((p[0] & 0xE0) == 0xC0) {
        cp = p[0] & 0x1F;
        extra = 1;
    } else if ((p[0] & 0xF0) == 0xE0) {
        cp = p[0] & 0x0F;
        extra = 2;
    } else if ((p[0] & 0xF8) == 0xF0) {
        cp = p[0] & 0x07;
        extra = 3;
    } else {
        *s += 1;
        return 0xFFFD;
    }
    for (int k = 1; k <= extra; k++) {
        if ((p[k] & 0xC0) != 0x80) {
            *s += k;
            return 0xFFFD;
        }
        cp = (cp << 6) | (p[k] & 0x3F);
    }
    *s += extra + 1;
    return cp;
}

/* Lays the string out at the current pixel size; with bmp, also draws it (coverage, w x h) with
 * the pen starting at x0 and the baseline at row base. Returns the advance width in whole pixels
 * (hinted advances, so glyphs sit on whole pixels and stay crisp). */
static int layout(render_context *rc, const char *text, unsigned char *bmp, int w, int h, int x0,
                  int base)
{
    FT_Face f = rc->face;
    int pen = x0;
    FT_UInt prev = 0;
    for (const char *s = text; *s;) {
        unsigned long cp = utf8_next(&s);
        FT_UInt gi = FT_Get_Char_Index(f, cp);
        if (prev && gi && FT_HAS_KERNING(f)) {
            FT_Vector k;
            if (!FT_Get_Kerning(f, prev, gi, FT_KERNING_DEFAULT, &k))
                pen += (int)((k.x + 32) >> 6);
        }
        if (FT_Load_Glyph(f, gi, FT_LOAD_TARGET_LIGHT | (bmp ? FT_LOAD_RENDER : 0)))
            continue;
        FT_GlyphSlot g = f->glyph;
        if (bmp && g->bitmap.pixel_mode == FT_PIXEL_MODE_GRAY) {
            for (unsigned row = 0; row < g->bitmap.rows; row++) {
                int y = base - g->bitmap_top + (int)row;
                if (y < 0 || y >= h)
                    continue;
                const unsigned char *src = g->bitmap.buffer + (long)row * g->bitmap.pitch;
                for (unsigned col = 0; col < g->bitmap.width; col++) {
                    int x = pen + g->bitmap_left + (int)col;
                    if (x < 0 || x >= w)
                        continue;
                    unsigned v = bmp[(size_t)y * w + x] + src[col];
                    bmp[(size_t)y * w + x] = (unsigned char)(v > 255 ? 255 : v);
                }
            }
        }
        pen += (int)((g->advance.x + 32) >> 6);
        prev = gi;
    }
    return pen - x0;
}

double canvas_text_width(render_context *rc, const char *utf8, double px)
{
    if (!utf8 || !*utf8)
        return 0;
    FT_Set_Pixel_Sizes(rc->face, 0, (FT_UInt)lround(px));
    return layout(rc, utf8, NULL, 0, 0, 0, 0);
}

double canvas_text(render_context *rc, const char *utf8, double px, double x, double y, double ha,
                   double va, int vertical, rgba8 c)
{
    if (!utf8 || !*utf8)
        return 0;
    flush(rc);
    FT_Set_Pixel_Sizes(rc->face, 0, (FT_UInt)lround(px));
    int asc = (int)((rc->face->size->metrics.ascender + 63) >> 6);
    int desc = (int)((-rc->face->size->metrics.descender + 63) >> 6);
    int adv = layout(rc, utf8, NULL, 0, 0, 0, 0);
    int pad = (int)lround(px * 0.3); /* italics and overhanging glyphs */
    int bw = adv + 2 * pad, bh = asc + desc;
    if (bw <= 0 || bh <= 0 || bw > RENDER_MAX_SIZE || bh > RENDER_MAX_SIZE)
        return adv;
    size_t need = (size_t)bw * bh * 2;
    if (need > rc->glyphs_size) {
        unsigned char *g = realloc(rc->glyphs, need);
        if (!g) {
            rc->oom = 1;
            return adv;
        }
        rc->glyphs = g;
        rc->glyphs_size = need;
    }
    unsigned char *bmp = rc->glyphs;
    memset(bmp, 0, (size_t)bw * bh);
    layout(rc, utf8, bmp, bw, bh, pad, asc);
    int tw = bw, th = bh;
    unsigned char *tex = bmp;
    /* Top-left pixel of the advance box, snapped to whole pixels so glyphs stay crisp. */
    int left, top;
    if (vertical) { /* rotate counter-clockwise: column c of the text becomes row (bw-1-c) */
        unsigned char *rot = bmp + (size_t)bw * bh;
        for (int r = 0; r < bh; r++)
            for (int col = 0; col < bw; col++)
                rot[(size_t)(bw - 1 - col) * bh + r] = bmp[(size_t)r * bw + col];
        tex = rot;
        tw = bh;
        th = bw;
        left = (int)lround(x - va * bh);
        top = (int)lround(y - (1 - ha) * adv) - pad;
    } else {
        left = (int)lround(x - ha * adv) - pad;
        top = (int)lround(y - va * bh);
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, rc->text_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, tw, th, 0, GL_RED, GL_UNSIGNED_BYTE, tex);
    glUseProgram(rc->prog_text);
    glUniform2f(rc->u_text_view, (float)rc->w, (float)rc->h);
    glUniform4f(rc->u_text_box, (float)left, (float)(rc->h - top - th), (float)tw, (float)th);
    glUniform4f(rc->u_text_color, c.r / 255.0f, c.g / 255.0f, c.b / 255.0f, c.a / 255.0f);
    glUniform1i(rc->u_text_tex, 0);
    glBindVertexArray(rc->vao_text);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    return adv;
}

double canvas_font_px(int width, int height)
{
    int m = width < height ? width : height;
    double px = width / 60.0;
    if (px > m / 12.0)
        px = m / 12.0;
    return px < 9 ? 9 : px > 96 ? 96 : floor(px + 0.5);
}
