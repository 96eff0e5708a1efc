/* scene_oct: a scene and the octree rasterized from it, opened together, as
 * the tools that check an .oct file against its scene's function need. */
#ifndef SCENE_OCT_H
#define SCENE_OCT_H

#include "common/expr/scene.h"
#include "format/oct.h"

/* Loads the scene and opens (validates) the octree. Returns EXIT_OK, or
 * EXIT_RUNTIME after printing why (nothing is left open). */
int scene_oct_open(const char *scene_path, const char *oct_path, scene **sc, oct_file **f);

#endif
