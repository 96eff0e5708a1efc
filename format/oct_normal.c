/* oct_normal: octahedral normal encoding (Meyer et al. 2010, "On Floating-Point
 * Normal Vectors"; Cigolle et al. 2014, JCGT 3(2)) in 2 x 12 bits, and the
 * voxel's plane offset in int8 steps. */
#include "format/oct_normal.h"
#include "format/oct.h"

#include <math.h>

#define OCT_NORMAL_STEPS 4095.0 /* 12 bits a coordinate: codes 0..4095 */

static double sign_not_zero(double v) { return v < 0.0 ? -1.0 : 1.0; }

static uint32_t quantize(double v) /* [-1,1] -> 0..4095, nearest */
{
    double q = floor((v * 0.5 + 0.5) * OCT_NORMAL_STEPS + 0.5);
    if (!(q >= 0.0)) q = 0.0; /* also catches NaN */
    if (q > OCT_NORMAL_STEPS) q = OCT_NORMAL_STEPS;
    return (uint32_t)q;
}

uint32_t oct_normal_encode(const double n[3])
{
    double l1 = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
    if (!(l1 > 0.0) || !isfinite(l1))
        return quantize(0.0) | (quantize(0.0) << 12); /* +z */
    double px = n[0] / l1, py = n[1] / l1;
    if (n[2] < 0.0) { /* fold the lower hemisphere over the diagonals */
        double fx = (1.0 - fabs(py)) * sign_not_zero(px);
        double fy = (1.0 - fabs(px)) * sign_not_zero(py);
        px = fx;
        py = fy;
    }
    return quantize(px) | (quantize(py) << 12);
}

void oct_normal_decode(uint32_t code, float n[3])
{
    double px = (double)(code & 0xfffu) / OCT_NORMAL_STEPS * 2.0 - 1.0;
    double py = (double)((code >> 12) & 0xfffu) / OCT_NORMAL_STEPS * 2.0 - 1.0;
    double pz = 1.0 - fabs(px) - fabs(py);
    if (pz < 0.0) {
        double fx = (1.0 - fabs(py)) * sign_not_zero(px);
        double fy = (1.0 - fabs(px)) * sign_not_zero(py);
        px = fx;
        py = fy;
    }
    double len = sqrt(px * px + py * py + pz * pz); /* >= 1/sqrt(3): never 0 */
    n[0] = (float)(px / len);
    n[1] = (float)(py / len);
    n[2] = (float)(pz / len);
}

int8_t oct_offset_encode(double d)
{
    double q = floor(d / OCT_OFFSET_UNIT + 0.5);
    if (!(q >= -127.0)) q = -127.0; /* also catches NaN */
    if (q > 127.0) q = 127.0;
    return (int8_t)q;
}

double oct_offset_decode(int8_t q) { return (double)q * OCT_OFFSET_UNIT; }

uint32_t oct_voxel_pack(const double normal[3], double offset)
{
    uint32_t off = (uint32_t)(uint8_t)oct_offset_encode(offset);
    return (oct_normal_encode(normal) & OCT_VOXEL_NORMAL_MASK) | (off << OCT_VOXEL_OFFSET_SHIFT);
}
