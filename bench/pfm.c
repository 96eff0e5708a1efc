/* pfm: PFM reader (header, byte order, bottom-to-top rows). */
#include "bench/pfm.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PFM_MAX_SIDE 32768u

/* Next whitespace-delimited token of the header into buf; -1 at EOF. */
static int token(FILE *f, char *buf, size_t cap)
{
    int c;
    do
        c = fgetc(f);
    while (c == ' ' || c == '\t' || c == '\n' || c == '\r');
    size_t n = 0;
    while (c != EOF && c != ' ' && c != '\t' && c != '\n' && c != '\r') {
        if (n + 1 >= cap)
            return -1;
        buf[n++] = (char)c;
        c = fgetc(f);
    }
    buf[n] = '\0';
    return n ? 0 : -1; /* the single whitespace after the scale is consumed */
}

int pfm_read(const char *path, pfm_image *img, const char **why)
{
    memset(img, 0, sizeof *img);
    FILE *f = fopen(path, "rb");
    if (!f) {
        *why = "open";
        return -1;
    }
    char magic[8], ws[16], hs[16], sc[32];
    char *end;
    if (token(f, magic, sizeof magic) || token(f, ws, sizeof ws) || token(f, hs, sizeof hs) ||
        token(f, sc, sizeof sc) || (strcmp(magic, "Pf") && strcmp(magic, "PF"))) {
        fclose(f);
        *why = "not a PFM file";
        return -1;
    }
    unsigned long w = strtoul(ws, &end, 10);
    int bad = *end != '\0';
    unsigned long h = strtoul(hs, &end, 10);
    bad |= *end != '\0';
    double scale = strtod(sc, &end);
    bad |= *end != '\0' || scale == 0.0;
    if (bad || w == 0 || h == 0 || w > PFM_MAX_SIDE || h > PFM_MAX_SIDE) {
        fclose(f);
        *why = "bad PFM header";
        return -1;
    }
    uint32_t ch = magic[1] == 'F' ? 3 : 1;
    size_t n = (size_t)w * h * ch;
    float *data = malloc(n * sizeof *data);
    uint8_t *row = malloc((size_t)w * ch * 4);
    if (!data || !row) {
        free(data);
        free(row);
        fclose(f);
        *why = "out of memory";
        return -1;
    }
    int little = scale < 0.0;
    for (size_t j = h; j-- > 0;) { /* stored bottom row first */
        if (fread(row, 4, (size_t)w * ch, f) != (size_t)w * ch) {
            free(data);
            free(row);
            fclose(f);
            *why = "truncated";
            return -1;
        }
        for (size_t i = 0; i < (size_t)w * ch; i++) {
            const uint8_t *b = row + 4 * i;
            uint32_t u = little ? (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                                      (uint32_t)b[3] << 24
                                : (uint32_t)b[3] | (uint32_t)b[2] << 8 | (uint32_t)b[1] << 16 |
                                      (uint32_t)b[0] << 24;
            memcpy(&data[j * w * ch + i], &u, 4);
        }
    }
    free(row);
    fclose(f);
    img->width = (uint32_t)w;
    img->height = (uint32_t)h;
    img->channels = ch;
    img->data = data;
    return 0;
}

void pfm_free(pfm_image *img)
{
    free(img->data);
    img->data = NULL;
}
