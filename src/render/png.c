/* PNG output through core/fileio (temporary file + rename) and frame-pattern expansion. */
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "render/render.h"

void render_image_free(render_image *img)
{
    if (!img)
        return;
    free(img->rgba);
    img->rgba = NULL;
    img->width = img->height = 0;
}

typedef struct png_failure {
    jmp_buf jmp;
    char msg[200];
} png_failure;

static void on_png_error(png_structp png, png_const_charp msg)
{
    png_failure *f = png_get_error_ptr(png);
    snprintf(f->msg, sizeof f->msg, "%s", msg);
    longjmp(f->jmp, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

core_status render_write_png(const render_image *img, const char *path, core_error *err)
{
    if (!img || !img->rgba || img->width < 1 || img->height < 1)
        return core_fail(err, CORE_ERR_ARG, "no image to write");
    unsigned char *row = malloc((size_t)img->width * 3);
    if (!row)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory writing '%s'", path);
    atomic_file f;
    core_status st = atomic_open(&f, path, err);
    if (st != CORE_OK) {
        free(row);
        return st;
    }
    png_failure fail = {.msg = ""};
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &fail, on_png_error,
                                              on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info || setjmp(fail.jmp)) {
        png_destroy_write_struct(&png, &info);
        atomic_abort(&f);
        free(row);
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path,
                         fail.msg[0] ? fail.msg : "out of memory");
    }
    png_init_io(png, f.fp);
    /* Fast settings: level 3 with the Sub and Up filters compresses these flat-coloured images
     * nearly as well as the defaults at a fraction of the time. */
    png_set_compression_level(png, 3);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB | PNG_FILTER_UP);
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE,
                 PNG_FILTER_TYPE_BASE);
    png_write_info(png, info);
    for (int y = 0; y < img->height; y++) {
        const unsigned char *src = img->rgba + (size_t)y * img->width * 4;
        for (int x = 0; x < img->width; x++)
            memcpy(row + 3 * x, src + 4 * x, 3);
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(row);
    return atomic_commit(&f, err);
}

core_status render_frame_path(const char *pattern, long frame, char *out, size_t size,
                              core_error *err)
{
    size_t n = 0;
    int conversions = 0;
    for (const char *p = pattern; *p; p++) {
        char piece[64];
        size_t len;
        if (*p != '%') {
            piece[0] = *p;
            len = 1;
        } else if (p[1] == '%') {
            piece[0] = '%';
            len = 1;
            p++;
        } else {
            const char *q = p + 1;
            int zero = *q == '0';
            if (zero)
                q++;
            int width = 0;
            while (*q >= '0' && *q <= '9' && width < 100)
                width = width * 10 + (*q++ - '0');
            if (*q != 'd' || width > 20 || conversions++)
                return core_fail(err, CORE_ERR_ARG,
                                 "file pattern '%s': one %%d, %%5d or %%05d-style frame number "
                                 "expected (write %%%% for a literal %%)", pattern);
            len = (size_t)snprintf(piece, sizeof piece, zero ? "%0*ld" : "%*ld", width, frame);
            p = q;
        }
        if (n + len >= size)
            return core_fail(err, CORE_ERR_ARG, "file name from '%s' too long", pattern);
        memcpy(out + n, piece, len);
        n += len;
    }
    out[n] = 0;
    return CORE_OK;
}
