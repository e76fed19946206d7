#pragma once
// What is measured on an assembly, in a wall box or a periodic cell (docs/physics.md §9, §11
// in part).
#include "core/simulation.hpp"

namespace grainlab::lab {

// Mean |net force| per particle over mean |contact force| per contact (particle-particle and
// particle-wall contacts). Quasi-static when small (e.g. < 0.01). Zero contacts gives 1.
double unbalancedForceRatio(const Simulation& sim);

// Love–Weber stress from contacts, compression positive: sigma = -(1/V) sum_p sum_c f^c (x^c - x^p)
// over all contacts of every particle, walls included (the per-particle form of [O] eq. 2.3). For a
// particle pair it reduces to f_AB (x) branch (the branch to the periodic image across a face). The
// full tensor: its skew part is a check (zero without contact moments at equilibrium).
Mat3 contactStress(const Simulation& sim);

// The wall box's stress that the contacts do not carry, compression positive:
// U = -(1/V) sum_p F_p (x) (x_p - x_0), F_p the net contact force on particle p (walls included;
// not damping or gravity), x_0 the box centre. Summing f (x) (x_c - x_0) over every contact of every
// particle leaves only the wall contacts, so that at any instant, in equilibrium or not,
//   wall stress = contactStress + U   (normal components; to the overlap / box length, since a wall
// contact's point lies half an overlap behind the wall plane).
// U vanishes at equilibrium; while the platens move it is the grains' inertia and the damping that
// hold the net forces. Zero in a periodic cell, whose boundary stress is the contact stress.
Mat3 unbalancedStress(const Simulation& sim);

// The boundary's stresses (sigma_xx, sigma_yy, sigma_zz), compression positive [Pa]: the wall
// stresses (mean of the two opposite walls) in a box, the symmetrised contact stress in a cell.
Vec3 boundaryStress(const Simulation& sim);
// Every wall's own stress (k = 2 axis + side) [Pa]; zeros in a periodic cell.
std::array<double, 6> singleWallStresses(const Simulation& sim);
// Lengths of the sample along x, y, z [m]: the box's, or the cell's diagonal of H.
Vec3 sampleLengths(const Simulation& sim);

double voidRatio(const Simulation& sim);
// Touching contacts of every particle, wall contacts included.
std::vector<int> contactsPerParticle(const Simulation& sim);
// Z = 2 Nc / Np over touching particle-particle contacts.
double coordinationNumber(const Simulation& sim);
// Kinetic energy of the particles' (fluctuating) translations and their rotations [J].
double kineticEnergy(const Simulation& sim);
// Elastic energy stored in the contact springs (normal, shear, moment) [J].
double elasticEnergy(const Simulation& sim);

}  // namespace grainlab::lab
