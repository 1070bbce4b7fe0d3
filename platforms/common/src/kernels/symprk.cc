/**
 * openmm_symprk native plugin: device code of the SymPRKIntegrator step, written in OpenMM's common compute
 * language (compiled at run time for OpenCL, CUDA or HIP).
 *
 * Host defines: NUM_ATOMS, PADDED_NUM_ATOMS, WORK_GROUP_SIZE (the projection reduction's block size),
 * MAX_SPEED2 (the squared blow-up speed).
 * velm.w is the inverse mass (0 for massless particles, which are never moved).  Forces are the
 * platform's 64-bit fixed-point accumulators (scaled by 2^32).  In mixed precision a position is
 * posq + posqCorrection, rebuilt and split again around every update, as OpenMM's own integrators do.
 */

inline DEVICE mixed4 symprkLoadPos(GLOBAL const real4* RESTRICT posq, GLOBAL const real4* RESTRICT posqCorrection, int index) {
#ifdef USE_MIXED_PRECISION
    real4 p1 = posq[index];
    real4 p2 = posqCorrection[index];
    return make_mixed4(p1.x+(mixed) p2.x, p1.y+(mixed) p2.y, p1.z+(mixed) p2.z, p1.w);
#else
    return posq[index];
#endif
}

inline DEVICE void symprkStorePos(GLOBAL real4* RESTRICT posq, GLOBAL real4* RESTRICT posqCorrection, int index, mixed4 pos) {
#ifdef USE_MIXED_PRECISION
    posq[index] = make_real4((real) pos.x, (real) pos.y, (real) pos.z, (real) pos.w);
    posqCorrection[index] = make_real4(pos.x-(real) pos.x, pos.y-(real) pos.y, pos.z-(real) pos.z, 0);
#else
    posq[index] = pos;
#endif
}

/** The type of the block reductions' sums and of the 3x3 solves: double where the device has it, else the mixed type. */
#ifdef SUPPORTS_DOUBLE_PRECISION
typedef double symprk_acc;
typedef double3 symprk_acc3;
#define make_symprk_acc3 make_double3
#else
typedef mixed symprk_acc;
typedef mixed3 symprk_acc3;
#define make_symprk_acc3 make_mixed3
#endif

/**
 * Sum the count per-thread values s[0..count-1] over one block of WORK_GROUP_SIZE threads into total[0..count-1]:
 * each thread's values go to partial[k*WORK_GROUP_SIZE+thread], then thread k adds column k in thread order (a
 * fixed order: deterministic).  Two barriers, none inside a loop (PoCL's kernel compiler is slow on those).
 */
inline DEVICE void symprkBlockSums(const symprk_acc* s, int count, LOCAL_ARG symprk_acc* partial, LOCAL_ARG symprk_acc* total) {
    const int tid = LOCAL_ID;
    for (int k = 0; k < count; k++)
        partial[k*WORK_GROUP_SIZE+tid] = s[k];
    SYNC_THREADS;
    if (tid < count) {
        symprk_acc sum = 0;
        for (int i = 0; i < WORK_GROUP_SIZE; i++)
            sum += partial[tid*WORK_GROUP_SIZE+i];
        total[tid] = sum;
    }
    SYNC_THREADS;
}

/** adj(I) rhs for the symmetric tensor I, and its determinant in *det: I^-1 rhs = adj(I) rhs / det. */
inline DEVICE symprk_acc3 symprkAdjugateTimes(symprk_acc Ixx, symprk_acc Iyy, symprk_acc Izz, symprk_acc Ixy, symprk_acc Ixz,
        symprk_acc Iyz, symprk_acc3 rhs, symprk_acc* det) {
    symprk_acc axx = Iyy*Izz-Iyz*Iyz, ayy = Ixx*Izz-Ixz*Ixz, azz = Ixx*Iyy-Ixy*Ixy;
    symprk_acc axy = Ixz*Iyz-Izz*Ixy, axz = Ixy*Iyz-Iyy*Ixz, ayz = Ixy*Ixz-Ixx*Iyz;
    *det = Ixx*axx+Ixy*axy+Ixz*axz;
    return make_symprk_acc3(axx*rhs.x+axy*rhs.y+axz*rhs.z, axy*rhs.x+ayy*rhs.y+ayz*rhs.z, axz*rhs.x+ayz*rhs.y+azz*rhs.z);
}

/**
 * I^-1 rhs for the inertia tensor about the centre of mass given by d = (sum m x^2, sum m y^2, sum m z^2) and
 * o = (sum m xy, sum m xz, sum m yz) (the operations of the host's SymPRKPlugin::solveInertia).  regularise: I
 * shifted by 1e-12 of its trace, 0 if still singular; else the exact inverse unless the determinant is below
 * 1e-10 trace^3 (a linear system: 2 rhs/trace).
 */
inline DEVICE symprk_acc3 symprkSolveInertia(symprk_acc3 d, symprk_acc3 o, symprk_acc3 rhs, int regularise) {
    const symprk_acc Ixx = d.y+d.z, Iyy = d.x+d.z, Izz = d.x+d.y, Ixy = -o.x, Ixz = -o.y, Iyz = -o.z;
    const symprk_acc trace = Ixx+Iyy+Izz;
    symprk_acc det;
    if (!regularise) {
        // the thermostat's kept rotation; a linear system (det below 1e-10 trace^3): w = 2 rhs/trace
        symprk_acc3 exact = symprkAdjugateTimes(Ixx, Iyy, Izz, Ixy, Ixz, Iyz, rhs, &det);
        if (isfinite(det) && fabs(det) > (symprk_acc) 1e-10*trace*trace*trace)
            return make_symprk_acc3(exact.x/det, exact.y/det, exact.z/det);
        if (isfinite(trace) && trace > 0)
            return make_symprk_acc3(2*rhs.x/trace, 2*rhs.y/trace, 2*rhs.z/trace);
        return make_symprk_acc3(0, 0, 0);
    }
    const symprk_acc shift = (symprk_acc) 1e-12*trace;
    symprk_acc3 shifted = symprkAdjugateTimes(Ixx+shift, Iyy+shift, Izz+shift, Ixy, Ixz, Iyz, rhs, &det);
    if (det == 0 || !isfinite(det))
        return make_symprk_acc3(0, 0, 0);
    return make_symprk_acc3(shifted.x/det, shifted.y/det, shifted.z/det);
}

/** Record the step in *badStep if a velocity is NaN, infinite or beyond the blow-up speed (NaN fails every <=). */
inline DEVICE void symprkCheckVelocity(mixed4 v, int checkStep, GLOBAL int* RESTRICT badStep) {
    if (checkStep > 0 && !(v.x*v.x+v.y*v.y+v.z*v.z <= (mixed) MAX_SPEED2) && badStep[0] == 0)
        badStep[0] = checkStep;
}

/*
 * The per-atom operations of the step, run as segments: a segment is up to four operations applied to each atom in
 * turn, in one launch (the host groups consecutive operations of the step plan that nothing global separates:
 * CommonSymPRKKernels.cpp).  An operation is an int4 (kind, argument, check step, 0) and a coefficient c:
 *   SYMPRK_OP_KICK            v += c F/m with the forces of slot `argument` (0: force0, 1: force1)
 *   SYMPRK_OP_KICK_PROJECTED  v += c (F/m - a_cm - alpha x (r - r_cm)), projection[] from symprkProjection
 *   SYMPRK_OP_DRIFT           x += c v (no constraints)
 *   SYMPRK_OP_DRIFT_DELTA     posDelta = c v (a constrained drift, part 1: the constraint algorithms correct it)
 *   SYMPRK_OP_DRIFT_APPLY     x += posDelta, v += (posDelta - c v)/c (part 2), plus the rigid velocity of rigid[]
 *                             (symprkRigidSums mode 0) when `argument` is 1
 *   SYMPRK_OP_EVENT_APPLY     v <- u + alpha (v - u), the thermostat event symprkEventSums left in event[]
 *   SYMPRK_OP_SAVE_VELOCITIES vBefore = v (before a velocity projection with exact momentum)
 *   SYMPRK_OP_RIGID_APPLY     v += the rigid velocity of rigid[] (symprkRigidSums mode 1) at x
 * A kick, a drift's apply check the velocities for a blow-up when their check step is > 0.  Each operation does
 * the arithmetic of its own launch: a position changed and then read again is stored and read back in between,
 * so that a segment gives, bit for bit, what its operations give one launch each.  Massless particles (velm.w 0)
 * never move; a drift's delta is 0 for them.
 */
#define SYMPRK_BUFFER_PARAMS GLOBAL real4* RESTRICT posq, GLOBAL real4* RESTRICT posqCorrection, GLOBAL mixed4* RESTRICT velm, \
        GLOBAL mixed4* RESTRICT posDelta, GLOBAL const mm_long* RESTRICT force0, GLOBAL const mm_long* RESTRICT force1, \
        GLOBAL const mixed* RESTRICT projection, GLOBAL symprk_acc* RESTRICT event, GLOBAL const mixed* RESTRICT rigid, \
        GLOBAL mixed4* RESTRICT vBefore, GLOBAL int* RESTRICT badStep, int withPositions
#define SYMPRK_BUFFER_ARGS posq, posqCorrection, velm, posDelta, force0, force1, projection, event, rigid, vBefore, badStep, \
        withPositions
#define SYMPRK_SEGMENT_PARAMS(P) int P##count, int4 P##op0, mixed P##c0, int4 P##op1, mixed P##c1, int4 P##op2, mixed P##c2, \
        int4 P##op3, mixed P##c3
#define SYMPRK_SEGMENT_ARGS(P) P##count, P##op0, P##c0, P##op1, P##c1, P##op2, P##c2, P##op3, P##c3

/** The position of atom index for an operation that reads it: loaded once, and stored and loaded again after a change. */
inline DEVICE void symprkReadPos(GLOBAL real4* RESTRICT posq, GLOBAL real4* RESTRICT posqCorrection, int index, mixed4* p,
        int* state) {
    // state: 0 not loaded, 1 loaded, 2 changed since loaded
    if (*state == 2)
        symprkStorePos(posq, posqCorrection, index, *p);
    if (*state != 1)
        *p = symprkLoadPos(posq, posqCorrection, index);
    *state = 1;
}

/** One operation on atom index (which has mass), its velocity in *v and its position in *p (see symprkReadPos). */
inline DEVICE void symprkAtomOp(int4 op, mixed c, int index, mixed4* v, mixed4* p, int* posState, SYMPRK_BUFFER_PARAMS) {
    const int kind = op.x;
    if (kind == SYMPRK_OP_KICK) {
        GLOBAL const mm_long* RESTRICT force = (op.y == 0 ? force0 : force1);
        const mixed scale = c/(mixed) 0x100000000;
        v->x += scale*force[index]*v->w;
        v->y += scale*force[index+PADDED_NUM_ATOMS]*v->w;
        v->z += scale*force[index+2*PADDED_NUM_ATOMS]*v->w;
        symprkCheckVelocity(*v, op.z, badStep);
    }
    else if (kind == SYMPRK_OP_KICK_PROJECTED) {
        GLOBAL const mm_long* RESTRICT force = (op.y == 0 ? force0 : force1);
        const mixed fscale = 1/(mixed) 0x100000000;
        const mixed3 com = make_mixed3(projection[0], projection[1], projection[2]);
        const mixed3 acm = make_mixed3(projection[3], projection[4], projection[5]);
        const mixed3 alpha = make_mixed3(projection[6], projection[7], projection[8]);
        symprkReadPos(posq, posqCorrection, index, p, posState);
        mixed3 r = make_mixed3(p->x-com.x, p->y-com.y, p->z-com.z);
        mixed ax = fscale*force[index]*v->w - acm.x - (alpha.y*r.z - alpha.z*r.y);
        mixed ay = fscale*force[index+PADDED_NUM_ATOMS]*v->w - acm.y - (alpha.z*r.x - alpha.x*r.z);
        mixed az = fscale*force[index+2*PADDED_NUM_ATOMS]*v->w - acm.z - (alpha.x*r.y - alpha.y*r.x);
        v->x += c*ax;
        v->y += c*ay;
        v->z += c*az;
        symprkCheckVelocity(*v, op.z, badStep);
    }
    else if (kind == SYMPRK_OP_DRIFT) {
        symprkReadPos(posq, posqCorrection, index, p, posState);
        p->x += c*v->x;
        p->y += c*v->y;
        p->z += c*v->z;
        *posState = 2;
    }
    else if (kind == SYMPRK_OP_DRIFT_DELTA)
        posDelta[index] = make_mixed4(c*v->x, c*v->y, c*v->z, 0);
    else if (kind == SYMPRK_OP_DRIFT_APPLY) {
#ifdef SUPPORTS_DOUBLE_PRECISION
        const double invCdt = 1.0/(double) c;
#else
        const float invCdt = 1.0f/c;
#endif
        symprkReadPos(posq, posqCorrection, index, p, posState);
        mixed4 d = posDelta[index];
        p->x += d.x;
        p->y += d.y;
        p->z += d.z;
        *posState = 2;
        v->x += (mixed) ((d.x-c*v->x)*invCdt);
        v->y += (mixed) ((d.y-c*v->y)*invCdt);
        v->z += (mixed) ((d.z-c*v->z)*invCdt);
        if (op.y) {
            mixed rx = p->x-rigid[0], ry = p->y-rigid[1], rz = p->z-rigid[2];
            v->x += rigid[3] + (rigid[7]*rz - rigid[8]*ry);
            v->y += rigid[4] + (rigid[8]*rx - rigid[6]*rz);
            v->z += rigid[5] + (rigid[6]*ry - rigid[7]*rx);
        }
        symprkCheckVelocity(*v, op.z, badStep);
    }
    else if (kind == SYMPRK_OP_EVENT_APPLY) {
        if (event[0] != 0) {
            const mixed alpha = event[1];
            mixed ux = event[2], uy = event[3], uz = event[4];
            if (withPositions) {
                const symprk_acc Rx = event[5], Ry = event[6], Rz = event[7];
                const mixed wx = event[8], wy = event[9], wz = event[10];
                symprkReadPos(posq, posqCorrection, index, p, posState);
                mixed rx = (mixed) (p->x-Rx), ry = (mixed) (p->y-Ry), rz = (mixed) (p->z-Rz);
                ux += wy*rz-wz*ry;
                uy += wz*rx-wx*rz;
                uz += wx*ry-wy*rx;
            }
            v->x = ux+alpha*(v->x-ux);
            v->y = uy+alpha*(v->y-uy);
            v->z = uz+alpha*(v->z-uz);
        }
    }
    else if (kind == SYMPRK_OP_SAVE_VELOCITIES)
        vBefore[index] = *v;
    else if (kind == SYMPRK_OP_RIGID_APPLY) {
        symprkReadPos(posq, posqCorrection, index, p, posState);
        mixed rx = p->x-rigid[0], ry = p->y-rigid[1], rz = p->z-rigid[2];
        v->x += rigid[3] + (rigid[7]*rz - rigid[8]*ry);
        v->y += rigid[4] + (rigid[8]*rx - rigid[6]*rz);
        v->z += rigid[5] + (rigid[6]*ry - rigid[7]*rx);
    }
}

/** The operations of one segment on atom index, in order; velocity and position written back once. */
inline DEVICE void symprkAtomSegment(int index, SYMPRK_SEGMENT_PARAMS(s), SYMPRK_BUFFER_PARAMS) {
    mixed4 v = velm[index];
    if (v.w == 0) {
        for (int k = 0; k < scount; k++) {
            const int kind = (k == 0 ? sop0.x : k == 1 ? sop1.x : k == 2 ? sop2.x : sop3.x);
            if (kind == SYMPRK_OP_DRIFT_DELTA)
                posDelta[index] = make_mixed4(0, 0, 0, 0);
            else if (kind == SYMPRK_OP_SAVE_VELOCITIES)
                vBefore[index] = v;
        }
        return;
    }
    int changesVelocity = 0;
    for (int k = 0; k < scount; k++) {
        const int kind = (k == 0 ? sop0.x : k == 1 ? sop1.x : k == 2 ? sop2.x : sop3.x);
        if (kind != SYMPRK_OP_DRIFT && kind != SYMPRK_OP_DRIFT_DELTA && kind != SYMPRK_OP_SAVE_VELOCITIES)
            changesVelocity = 1;
    }
    mixed4 p = make_mixed4(0, 0, 0, 0);
    int posState = 0;
    if (scount > 0)
        symprkAtomOp(sop0, sc0, index, &v, &p, &posState, SYMPRK_BUFFER_ARGS);
    if (scount > 1)
        symprkAtomOp(sop1, sc1, index, &v, &p, &posState, SYMPRK_BUFFER_ARGS);
    if (scount > 2)
        symprkAtomOp(sop2, sc2, index, &v, &p, &posState, SYMPRK_BUFFER_ARGS);
    if (scount > 3)
        symprkAtomOp(sop3, sc3, index, &v, &p, &posState, SYMPRK_BUFFER_ARGS);
    if (posState == 2)
        symprkStorePos(posq, posqCorrection, index, p);
    if (changesVelocity)
        velm[index] = v;
}

/** One segment over all atoms, on the whole grid. */
KERNEL void symprkSegment(SYMPRK_SEGMENT_PARAMS(s), SYMPRK_BUFFER_PARAMS) {
    for (int index = GLOBAL_ID; index < NUM_ATOMS; index += GLOBAL_SIZE)
        symprkAtomSegment(index, SYMPRK_SEGMENT_ARGS(s), SYMPRK_BUFFER_ARGS);
}


/**
 * The exact-momentum projection, run as one block of WORK_GROUP_SIZE threads: centre of mass r_cm, net force,
 * torque about r_cm and the inertia tensor about r_cm (per-thread sums in the mixed type, block sums in
 * symprk_acc), then projection[0..2] = r_cm, [3..5] = a_cm = F/M, [6..8] = alpha = I^-1 tau (I regularised by
 * 1e-12 of its trace).  Massless particles are excluded.
 */
KERNEL void symprkProjection(GLOBAL const real4* RESTRICT posq, GLOBAL const real4* RESTRICT posqCorrection,
        GLOBAL const mixed4* RESTRICT velm, GLOBAL const mm_long* RESTRICT force, GLOBAL mixed* RESTRICT projection) {
    LOCAL symprk_acc partial[9*WORK_GROUP_SIZE];
    LOCAL symprk_acc total[9];
    const mixed fscale = 1/(mixed) 0x100000000;
    mixed s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0;
    for (int index = LOCAL_ID; index < NUM_ATOMS; index += WORK_GROUP_SIZE) {
        mixed4 v = velm[index];
        if (v.w != 0) {
            mixed mass = 1/v.w;
            mixed4 p = symprkLoadPos(posq, posqCorrection, index);
            s0 += mass;
            s1 += mass*p.x;
            s2 += mass*p.y;
            s3 += mass*p.z;
            s4 += fscale*force[index];
            s5 += fscale*force[index+PADDED_NUM_ATOMS];
            s6 += fscale*force[index+2*PADDED_NUM_ATOMS];
        }
    }
    const symprk_acc first[7] = {s0, s1, s2, s3, s4, s5, s6};
    symprkBlockSums(first, 7, partial, total);
    const mixed m = total[0];
    const mixed invM = (m == 0 ? (mixed) 0 : 1/m);
    const mixed cx = total[1]*invM, cy = total[2]*invM, cz = total[3]*invM;
    const mixed fx = total[4], fy = total[5], fz = total[6];
    mixed tx = 0, ty = 0, tz = 0, dxx = 0, dyy = 0, dzz = 0, oxy = 0, oxz = 0, oyz = 0;
    for (int index = LOCAL_ID; index < NUM_ATOMS; index += WORK_GROUP_SIZE) {
        mixed4 v = velm[index];
        if (v.w != 0) {
            mixed mass = 1/v.w;
            mixed4 p = symprkLoadPos(posq, posqCorrection, index);
            mixed rx = p.x-cx, ry = p.y-cy, rz = p.z-cz;
            mixed gx = fscale*force[index], gy = fscale*force[index+PADDED_NUM_ATOMS], gz = fscale*force[index+2*PADDED_NUM_ATOMS];
            tx += ry*gz-rz*gy;
            ty += rz*gx-rx*gz;
            tz += rx*gy-ry*gx;
            dxx += mass*rx*rx;
            dyy += mass*ry*ry;
            dzz += mass*rz*rz;
            oxy += mass*rx*ry;
            oxz += mass*rx*rz;
            oyz += mass*ry*rz;
        }
    }
    const symprk_acc second[9] = {tx, ty, tz, dxx, dyy, dzz, oxy, oxz, oyz};
    symprkBlockSums(second, 9, partial, total);
    if (LOCAL_ID == 0) {
        const symprk_acc3 alpha = symprkSolveInertia(make_symprk_acc3(total[3], total[4], total[5]),
                make_symprk_acc3(total[6], total[7], total[8]), make_symprk_acc3(total[0], total[1], total[2]), 1);
        projection[0] = cx;
        projection[1] = cy;
        projection[2] = cz;
        projection[3] = fx*invM;
        projection[4] = fy*invM;
        projection[5] = fz*invM;
        projection[6] = alpha.x;
        projection[7] = alpha.y;
        projection[8] = alpha.z;
    }
}

/**
 * Exact momentum with constraints: the net momentum dP and angular momentum dL (about the origin) of the
 * constraint impulses, which vanish in exact arithmetic, and the rigid-body velocity w + gamma x (r - c)
 * that cancels their round-off values: rigid[0..2] = c, [3..5] = w = -dP/M, [6..8] = gamma = I_c^-1 (c x dP - dL).
 * mode 0, before symprkDriftApply: impulses m (d - c*dt*v)/(c*dt) about the pre-drift positions, r = x + d.
 * mode 1, after the velocity projection: impulses m (v - vBefore) about r = x.  One block of WORK_GROUP_SIZE.
 */
KERNEL void symprkRigidSums(int mode, mixed cdt, GLOBAL const real4* RESTRICT posq, GLOBAL const real4* RESTRICT posqCorrection,
        GLOBAL const mixed4* RESTRICT velm, GLOBAL const mixed4* RESTRICT posDelta, GLOBAL const mixed4* RESTRICT vBefore,
        GLOBAL mixed* RESTRICT rigid) {
    LOCAL symprk_acc partial[10*WORK_GROUP_SIZE];
    LOCAL symprk_acc total[10];
    mixed s[10];
    for (int k = 0; k < 10; k++)
        s[k] = 0;
    for (int index = LOCAL_ID; index < NUM_ATOMS; index += WORK_GROUP_SIZE) {
        mixed4 v = velm[index];
        if (v.w != 0) {
            mixed mass = 1/v.w;
            mixed4 x = symprkLoadPos(posq, posqCorrection, index);
            mixed3 r, J;
            if (mode == 0) {
                mixed4 d = posDelta[index];
                r = make_mixed3(x.x+d.x, x.y+d.y, x.z+d.z);
                J = make_mixed3(mass*(d.x-cdt*v.x)/cdt, mass*(d.y-cdt*v.y)/cdt, mass*(d.z-cdt*v.z)/cdt);
            }
            else {
                mixed4 vb = vBefore[index];
                r = make_mixed3(x.x, x.y, x.z);
                J = make_mixed3(mass*(v.x-vb.x), mass*(v.y-vb.y), mass*(v.z-vb.z));
            }
            s[0] += mass;
            s[1] += mass*r.x;
            s[2] += mass*r.y;
            s[3] += mass*r.z;
            s[4] += J.x;
            s[5] += J.y;
            s[6] += J.z;
            s[7] += x.y*J.z-x.z*J.y;
            s[8] += x.z*J.x-x.x*J.z;
            s[9] += x.x*J.y-x.y*J.x;
        }
    }
    symprk_acc first[10];
    for (int k = 0; k < 10; k++)
        first[k] = s[k];
    symprkBlockSums(first, 10, partial, total);
    const mixed M = total[0];
    const mixed invM = (M == 0 ? (mixed) 0 : 1/M);
    const mixed cx = total[1]*invM, cy = total[2]*invM, cz = total[3]*invM;
    const mixed px = total[4], py = total[5], pz = total[6];
    const mixed lx = total[7], ly = total[8], lz = total[9];
    for (int k = 0; k < 6; k++)
        s[k] = 0;
    for (int index = LOCAL_ID; index < NUM_ATOMS; index += WORK_GROUP_SIZE) {
        mixed4 v = velm[index];
        if (v.w != 0) {
            mixed mass = 1/v.w;
            mixed4 x = symprkLoadPos(posq, posqCorrection, index);
            if (mode == 0) {
                mixed4 d = posDelta[index];
                x.x += d.x;
                x.y += d.y;
                x.z += d.z;
            }
            mixed rx = x.x-cx, ry = x.y-cy, rz = x.z-cz;
            s[0] += mass*rx*rx;
            s[1] += mass*ry*ry;
            s[2] += mass*rz*rz;
            s[3] += mass*rx*ry;
            s[4] += mass*rx*rz;
            s[5] += mass*ry*rz;
        }
    }
    symprk_acc second[6];
    for (int k = 0; k < 6; k++)
        second[k] = s[k];
    symprkBlockSums(second, 6, partial, total);
    if (LOCAL_ID == 0) {
        // right-hand side c x dP - dL
        const symprk_acc3 b = make_symprk_acc3((cy*pz-cz*py)-lx, (cz*px-cx*pz)-ly, (cx*py-cy*px)-lz);
        const symprk_acc3 gamma = symprkSolveInertia(make_symprk_acc3(total[0], total[1], total[2]),
                make_symprk_acc3(total[3], total[4], total[5]), b, 1);
        rigid[0] = cx;
        rigid[1] = cy;
        rigid[2] = cz;
        rigid[3] = -px*invM;
        rigid[4] = -py*invM;
        rigid[5] = -pz*invM;
        rigid[6] = gamma.x;
        rigid[7] = gamma.y;
        rigid[8] = gamma.z;
    }
}

/*
 * Thermostat (stochastic velocity rescaling), the whole event on the device (no host transfer): the operations of
 * the host's SymPRKThermostat::event and rescalingFactor.  One block of WORK_GROUP_SIZE threads, sums in symprk_acc
 * added in a fixed order, in two passes over the particles with mass: (1) M, sum m (x - x_0) (x_0: the first atom's
 * position, so that nothing cancels far from the origin), P, sum m v.v and the chi-squared variate, (2) about the
 * centre of mass R: sum m |v - V|^2 and, when the rotation is kept (withPositions), the second moments and
 * L = sum m r x (v - V).  The noise: the dof standard normals n_k (k < dof) from OpenMM's generator,
 * component k%4 of random[randomIndex + k/4]: r1 = n_0, chi2 = sum_{k=1}^{dof-1} n_k^2.
 * Writes event[] = {apply, alpha, V (3), R (3), w (3)} for the apply (SYMPRK_OP_EVENT_APPLY) and updates
 * state[] = {heat-bath energy, total kinetic energy after the event, skipped events, 1 if this event was skipped else 0,
 * peculiar kinetic energy after the event}
 * (SymPRKThermostat::RunState).
 */
#define SYMPRK_EVENT_SIZE 11

/**
 * This thread's share of an event's chi-squared variate: sum of n_k^2 for 1 <= k < dof over the event's standard
 * normals n_k, component k%4 of random[randomIndex + k/4] (n_0 is the event's r1).
 */
inline DEVICE symprk_acc symprkNoiseSquares(GLOBAL const float4* RESTRICT random, int randomIndex, int dof) {
    symprk_acc sum = 0;
    const int numRandom = (dof+3)/4;
    for (int j = LOCAL_ID; j < numRandom; j += WORK_GROUP_SIZE) {
        const float4 r = random[randomIndex+j];
        const float n[4] = {r.x, r.y, r.z, r.w};
        for (int q = 0; q < 4; q++) {
            const int k = 4*j+q;
            if (k >= 1 && k < dof)
                sum += (symprk_acc) n[q]*(symprk_acc) n[q];
        }
    }
    return sum;
}

/**
 * The noise of one event as symprkThermostatEvent draws it (the same numbers, the same sums in the same order), for
 * tests of the random numbers: out[2*sample] = r1, out[2*sample+1] = chi2.  One block of WORK_GROUP_SIZE threads.
 */
KERNEL void symprkThermostatNoise(GLOBAL const float4* RESTRICT random, int randomIndex, int dof, GLOBAL symprk_acc* RESTRICT out,
        int sample) {
    LOCAL symprk_acc partial[WORK_GROUP_SIZE];
    LOCAL symprk_acc total[1];
    symprk_acc s[1];
    s[0] = symprkNoiseSquares(random, randomIndex, dof);
    symprkBlockSums(s, 1, partial, total);
    if (LOCAL_ID == 0) {
        out[2*sample] = (symprk_acc) random[randomIndex].x;
        out[2*sample+1] = total[0];
    }
}

inline DEVICE void symprkEventSums(GLOBAL const real4* RESTRICT posq, GLOBAL const real4* RESTRICT posqCorrection,
        GLOBAL const mixed4* RESTRICT velm, int withPositions, GLOBAL const float4* RESTRICT random, int randomIndex, int dof,
        symprk_acc target, symprk_acc c, GLOBAL symprk_acc* RESTRICT event, GLOBAL symprk_acc* RESTRICT state,
        LOCAL_ARG symprk_acc* partial, LOCAL_ARG symprk_acc* total) {
    const int tid = LOCAL_ID;
    const mixed4 origin = symprkLoadPos(posq, posqCorrection, 0);
    symprk_acc s[10];
    for (int k = 0; k < 10; k++)
        s[k] = 0;
    for (int index = tid; index < NUM_ATOMS; index += WORK_GROUP_SIZE) {
        mixed4 v = velm[index];
        if (v.w != 0) {
            const symprk_acc m = 1/(symprk_acc) v.w;
            const mixed4 p = symprkLoadPos(posq, posqCorrection, index);
            const symprk_acc vx = v.x, vy = v.y, vz = v.z;
            s[0] += m;
            s[1] += m*(symprk_acc) (p.x-origin.x);
            s[2] += m*(symprk_acc) (p.y-origin.y);
            s[3] += m*(symprk_acc) (p.z-origin.z);
            s[4] += m*vx;
            s[5] += m*vy;
            s[6] += m*vz;
            s[7] += m*(vx*vx+vy*vy+vz*vz);
        }
    }
    s[8] = symprkNoiseSquares(random, randomIndex, dof);
    symprkBlockSums(s, 9, partial, total);
    const symprk_acc M = total[0];
    const symprk_acc invM = (M == 0 ? (symprk_acc) 0 : 1/M);
    const symprk_acc Rx = (symprk_acc) origin.x+total[1]*invM, Ry = (symprk_acc) origin.y+total[2]*invM,
            Rz = (symprk_acc) origin.z+total[3]*invM;
    const symprk_acc Vx = total[4]*invM, Vy = total[5]*invM, Vz = total[6]*invM;
    const symprk_acc twiceKinetic = total[7], chi2 = total[8];
    for (int k = 0; k < 10; k++)
        s[k] = 0;
    // Pass (2): the same walk over the particles with mass as pass (1), now about the centre of mass (the two
    // passes are the point of the event's arithmetic, see above, so their loop heads are alike on purpose).
    for (int index = tid; index < NUM_ATOMS; index += WORK_GROUP_SIZE) {
        mixed4 v = velm[index];
        if (v.w != 0) {
            const symprk_acc m = 1/(symprk_acc) v.w;
            const symprk_acc ux = v.x-Vx, uy = v.y-Vy, uz = v.z-Vz;
            s[0] += m*(ux*ux+uy*uy+uz*uz);
            if (withPositions) {
                const mixed4 p = symprkLoadPos(posq, posqCorrection, index);
                const symprk_acc rx = p.x-Rx, ry = p.y-Ry, rz = p.z-Rz;
                s[1] += m*rx*rx;
                s[2] += m*ry*ry;
                s[3] += m*rz*rz;
                s[4] += m*rx*ry;
                s[5] += m*rx*rz;
                s[6] += m*ry*rz;
                s[7] += m*(ry*uz-rz*uy);
                s[8] += m*(rz*ux-rx*uz);
                s[9] += m*(rx*uy-ry*ux);
            }
        }
    }
    symprkBlockSums(s, 10, partial, total);
    if (tid == 0) {
        symprk_acc apply = 0, alpha = 1;
        symprk_acc3 w = make_symprk_acc3(0, 0, 0);
        const symprk_acc totalKinetic = (symprk_acc) 0.5*twiceKinetic;
        symprk_acc kinetic = (symprk_acc) 0.5*total[0];
        if (withPositions) {
            const symprk_acc3 L = make_symprk_acc3(total[7], total[8], total[9]);
            w = symprkSolveInertia(make_symprk_acc3(total[1], total[2], total[3]), make_symprk_acc3(total[4], total[5], total[6]),
                                   L, 0);
            kinetic -= (symprk_acc) 0.5*(L.x*w.x+L.y*w.y+L.z*w.z);
        }
        if (M > 0 && isfinite(kinetic) && isfinite(totalKinetic)) {
            state[1] = totalKinetic;
            state[3] = 0;
            state[4] = kinetic;
            if (!(kinetic > (symprk_acc) 1e-10*totalKinetic)) {
                state[2] += 1;  // at rest or a rigid motion: only round-off to scale
                state[3] = 1;
            }
            else {
                // SymPRKThermostat::rescalingFactor
                const symprk_acc r1 = (symprk_acc) random[randomIndex].x;
                const symprk_acc sd = target/dof;
                const symprk_acc knew = c*kinetic + (1-c)*sd*(r1*r1+chi2) + 2*r1*sqrt(c*(1-c)*kinetic*sd);
                alpha = sqrt((knew > 0 ? knew : (symprk_acc) 0)/kinetic);
                if (c < 1 && r1+sqrt(c*kinetic/((1-c)*sd)) < 0)
                    alpha = -alpha;
                if (isfinite(alpha) && isfinite(knew)) {
                    apply = 1;
                    state[0] -= knew-kinetic;
                    state[1] = totalKinetic-kinetic+knew;
                    state[4] = knew;
                }
                else
                    alpha = 1;
            }
        }
        event[0] = apply;
        event[1] = alpha;
        event[2] = Vx;
        event[3] = Vy;
        event[4] = Vz;
        event[5] = Rx;
        event[6] = Ry;
        event[7] = Rz;
        event[8] = w.x;
        event[9] = w.y;
        event[10] = w.z;
    }
}

/**
 * A thermostat event in one launch of one block of WORK_GROUP_SIZE threads: the segment `pre` on every atom, the
 * event's sums and factor (symprkEventSums, into event[] and state[]), then the segment `post` (the event's apply and
 * what follows it up to the next operation that needs the whole device: constraints, forces, another reduction).
 * Each thread takes the same atoms in every pass.  With both segments empty it is the event's reduction alone, and
 * the apply runs in the grid segment after it (systems above the host's one-block limit).
 */
KERNEL void symprkEventBlock(SYMPRK_SEGMENT_PARAMS(pre), SYMPRK_SEGMENT_PARAMS(post), SYMPRK_BUFFER_PARAMS,
        GLOBAL const float4* RESTRICT random, int randomIndex, int dof, symprk_acc target, symprk_acc decay,
        GLOBAL symprk_acc* RESTRICT state) {
    LOCAL symprk_acc partial[10*WORK_GROUP_SIZE];
    LOCAL symprk_acc total[10];
    if (precount > 0) {
        for (int index = LOCAL_ID; index < NUM_ATOMS; index += WORK_GROUP_SIZE)
            symprkAtomSegment(index, SYMPRK_SEGMENT_ARGS(pre), SYMPRK_BUFFER_ARGS);
        SYNC_THREADS;  // the sums read the first atom's position (every thread) after it
    }
    symprkEventSums(posq, posqCorrection, velm, withPositions, random, randomIndex, dof, target, decay,
                    event, state, partial, total);
    if (postcount > 0) {
        SYNC_THREADS;  // event[] is written by thread 0
        for (int index = LOCAL_ID; index < NUM_ATOMS; index += WORK_GROUP_SIZE)
            symprkAtomSegment(index, SYMPRK_SEGMENT_ARGS(post), SYMPRK_BUFFER_ARGS);
    }
}
