/* oct_normal: the voxel record's 24-bit octahedral normal and 8-bit plane
 * offset (FORMAT.md, "Voxel record"). Shared by the writer's producer
 * (rasterize) and the reader's consumer (render). */
#ifndef OCT_NORMAL_H
#define OCT_NORMAL_H

#include <stdint.h>

/* Direction -> 24-bit octahedral code (12 bits a coordinate, rounded to
 * nearest): the vector need not be unit, its L1 norm is divided out. A
 * zero or non-finite vector encodes +z. */
uint32_t oct_normal_encode(const double n[3]);

/* 24-bit code -> unit vector (renormalised, in float). */
void oct_normal_decode(uint32_t code, float n[3]);

/* Signed plane offset in voxel edges -> int8 steps of OCT_OFFSET_UNIT,
 * rounded to nearest and clamped to [-127, 127]. */
int8_t oct_offset_encode(double d);
double oct_offset_decode(int8_t q);

/* The whole 32-bit voxel record. */
uint32_t oct_voxel_pack(const double normal[3], double offset);

#endif
