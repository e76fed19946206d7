#pragma once
// Random loose placement of spheres without overlaps in a cubic box or periodic cell (docs/laboratory.md §1).
#include <vector>

#include "core/simulation.hpp"
#include "lab/random.hpp"

namespace grainlab::lab {

// Places spheres of the given diameters [m] at random in a cube whose volume is
// (1 + voidRatio) times the solid volume, largest first, rejecting overlaps (in a periodic cell
// with every image). The cube grows by 5 % and placement restarts if a sphere finds no room.
// Particles are then renumbered in cell order, so that neighbours in space are neighbours in
// memory, and given ids in that order. Sets the walls on the cube's faces, or the cell to the cube,
// as sim.boundary says.
void placeLoose(std::vector<double> diameters, double density, double voidRatio, Rng& rng, Simulation& sim);

// test.boundary = "membrane": spheres placed as placeLoose does, in a cylinder of height/diameter
// `aspect` (the cloud at voidRatio), its axis vertical; the box's z walls (the platens) on its end
// faces, its x and y walls well clear of it; the membrane's bins about binSide [m] square once the
// sample has shrunk linearly by `shrink` (sim.membrane set up and measured).
struct CylinderPlacement {
  double radius = 0.0, height = 0.0;  // of the cloud [m]
};
CylinderPlacement placeCylinder(std::vector<double> diameters, double density, double voidRatio, double aspect,
                                double binSide, double shrink, Rng& rng, Simulation& sim);

// sample.method = "deposition": spheres placed at random, without overlaps, in a column (a cloud of
// void ratio voidRatio) above the floor of a wall box with a square footprint on which a bed of
// about bedVoidRatio would be a cube; the cloud's lowest point is dropHeight above the floor. The
// box (walls on its faces) encloses the cloud; the column grows by 5 % if a sphere finds no room.
struct ColumnPlacement {
  double width = 0.0;               // side of the footprint [m]
  double cloudHeight = 0.0;         // height of the cloud [m]
  double cloudSolidFraction = 0.0;  // solid volume / cloud volume
};
ColumnPlacement placeColumn(std::vector<double> diameters, double density, double voidRatio, double bedVoidRatio,
                            double dropHeight, Rng& rng, Simulation& sim);

// sample.method = "under-compaction": appends spheres, placed at random without overlaps, in the
// slab [0, width]^2 x [zBottom, zBottom + h] of a wall box, h such that the slab's cloud has the
// given void ratio (grown by 5 % if a sphere finds no room), in cell order after the particles
// already there (new ids follow theirs). zBottom at or above every grain already there: the slab
// overlaps none of them. Returns h. The box is left as it is.
double appendSlab(std::vector<double> diameters, double density, double voidRatio, double width, double zBottom, Rng& rng,
                  Simulation& sim);

// The solid volume of spheres between the horizontal planes z0 < z1 (spherical caps): the void
// ratio profile of a layered sample. Spheres only.
double solidVolumeBetween(const Particles& particles, double z0, double z1);

// [O] §5.1: n^3 equal spheres of diameter d on a simple cubic lattice of spacing d (just touching),
// filling the cube of side n d: the cell (periodic) or the box of walls.
void placeLattice(int n, double d, double density, Simulation& sim);

}  // namespace grainlab::lab
