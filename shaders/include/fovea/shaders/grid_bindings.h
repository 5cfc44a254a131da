// Descriptor binding indices of the grid pass (grid_generate.comp) and its live-tile list
// (grid_live_list.comp), one definition for the GLSL and gpu/src/grid_pass.cpp.
#ifndef FOVEA_SHADERS_GRID_BINDINGS_H
#define FOVEA_SHADERS_GRID_BINDINGS_H

// grid_generate.comp, set 0
#define GRID_BINDING_PARAMS 0      // uniform GridParams
#define GRID_BINDING_COLUMNS 1     // GridColumn per column (the column table)
#define GRID_BINDING_MASK 2        // the view's hidden-area bitmask
#define GRID_BINDING_SAMPLES 3     // GridSample per cell (written)
#define GRID_BINDING_COUNTS 4      // GridCounts
#define GRID_BINDING_HISTORY 5     // per cell: its last frames' liveness (live_cells.h)
#define GRID_BINDING_TILE_STATE 6  // per tile: live and reset bits
#define GRID_BINDING_COUNT 7

// grid_live_list.comp, set 0
#define LIVE_LIST_BINDING_COUNTS 0
#define LIVE_LIST_BINDING_LIST 1  // header (indirect dispatches) and the listed tiles
#define LIVE_LIST_BINDING_TILE_STATE 2
#define LIVE_LIST_BINDING_COUNT 3

#endif
