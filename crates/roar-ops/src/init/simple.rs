//! The local rule that keeps the exterior's regrowth (module `solid`) from cutting tunnels:
//! a solid voxel may join the exterior only if its exterior neighbours form exactly one group.
//!
//! Connectivity: the exterior is 6-connected (the flood fill's). With `N18(x)` the voxels sharing
//! a face or an edge with `x`, let `T6(x)` be the number of 6-connected groups of exterior voxels
//! in `N18(x)` that touch a face of `x` (Bertrand & Malandain's topological number). Turning `x`
//! exterior
//! - with `T6 = 0` would start a cavity;
//! - with `T6 ≥ 2` joins two exterior regions through `x`: where they are one region further
//!   away, that cuts a tunnel through a wall thinner than a voxel;
//! - with `T6 = 1` only moves the boundary. It may still cut a thin solid bridge (the solid
//!   around `x` falls apart locally), which removes a handle or separates two parts the
//!   dilation had joined; that is what the closing's regrowth is for.
//!
//! The neighbourhood is a 26-bit mask; groups are counted by flooding masks through precomputed
//! adjacency masks, so a test is a few dozen bit operations.

/// Offsets of the 26 neighbours, bit `i` of a neighbourhood mask.
const OFFSETS: [[i32; 3]; 26] = {
    let mut out = [[0i32; 3]; 26];
    let mut n = 0;
    let mut dz = -1;
    while dz <= 1 {
        let mut dy = -1;
        while dy <= 1 {
            let mut dx = -1;
            while dx <= 1 {
                if !(dx == 0 && dy == 0 && dz == 0) {
                    out[n] = [dx, dy, dz];
                    n += 1;
                }
                dx += 1;
            }
            dy += 1;
        }
        dz += 1;
    }
    out
};

/// Per neighbour: the neighbours sharing a face with it; and the N18 and face masks of the
/// centre.
struct Tables {
    adj6: [u32; 26],
    adj26: [u32; 26],
    n18: u32,
    n6: u32,
}

const TABLES: Tables = {
    let mut t = Tables {
        adj6: [0; 26],
        adj26: [0; 26],
        n18: 0,
        n6: 0,
    };
    let mut i = 0;
    while i < 26 {
        let a = OFFSETS[i];
        let norm = a[0].abs() + a[1].abs() + a[2].abs();
        if norm <= 2 {
            t.n18 |= 1 << i;
        }
        if norm == 1 {
            t.n6 |= 1 << i;
        }
        let mut j = 0;
        while j < 26 {
            let b = OFFSETS[j];
            let d = (a[0] - b[0]).abs() + (a[1] - b[1]).abs() + (a[2] - b[2]).abs();
            if d == 1 {
                t.adj6[i] |= 1 << j;
            }
            let touching =
                (a[0] - b[0]).abs() <= 1 && (a[1] - b[1]).abs() <= 1 && (a[2] - b[2]).abs() <= 1;
            if i != j && touching {
                t.adj26[i] |= 1 << j;
            }
            j += 1;
        }
        i += 1;
    }
    t
};

/// Groups of `set` (connected through `adj`) that contain a voxel of `seeds`.
fn groups(set: u32, adj: &[u32; 26], seeds: u32) -> u32 {
    let mut remaining = set;
    let mut count = 0;
    while remaining & seeds != 0 {
        let start = 1u32 << (remaining & seeds).trailing_zeros();
        let mut group = start;
        let mut frontier = start;
        while frontier != 0 {
            let i = frontier.trailing_zeros() as usize;
            frontier &= frontier - 1;
            let new = adj[i] & remaining & !group;
            group |= new;
            frontier |= new;
        }
        remaining &= !group;
        count += 1;
    }
    count
}

/// `T6` of a voxel whose exterior neighbours are `exterior` (26-bit mask, bit order of
/// [`offsets`]): the number of exterior groups it would join (module docs).
pub(crate) fn exterior_groups(exterior: u32) -> u32 {
    groups(exterior & TABLES.n18, &TABLES.adj6, TABLES.n6)
}

/// Whether a solid voxel whose exterior neighbours are `exterior` may turn exterior without
/// changing the topology of the solid or of the exterior (Bertrand & Malandain: `T6 = 1` for the
/// 6-connected exterior and `T26 ≤ 1` for the 26-connected solid; `T26 = 0` is a lone voxel,
/// whose removal only drops itself). Cuts no tunnel, opens no cavity, breaks no bridge.
pub(crate) fn is_simple(exterior: u32) -> bool {
    const ALL: u32 = (1 << 26) - 1;
    exterior_groups(exterior) == 1 && groups(!exterior & ALL, &TABLES.adj26, ALL) <= 1
}

/// The 26 neighbour offsets (bit order of the masks [`is_simple`] takes).
pub(crate) fn offsets() -> &'static [[i32; 3]; 26] {
    &OFFSETS
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(pred: impl Fn([i32; 3]) -> bool) -> u32 {
        (0..26).filter(|&i| pred(OFFSETS[i])).map(|i| 1 << i).sum()
    }

    #[test]
    fn a_voxel_under_a_flat_exterior_joins_one_group() {
        assert_eq!(exterior_groups(mask(|o| o[2] == 1)), 1);
    }

    #[test]
    fn a_voxel_in_a_wall_between_two_exterior_layers_joins_two() {
        // Opening it would cut a tunnel through the wall.
        assert_eq!(exterior_groups(mask(|o| o[2] != 0)), 2);
    }

    #[test]
    fn a_buried_voxel_or_one_touching_the_exterior_at_a_corner_joins_none() {
        assert_eq!(exterior_groups(0), 0);
        assert_eq!(exterior_groups(mask(|o| o == [1, 1, 1])), 0);
    }

    #[test]
    fn the_middle_of_a_thin_rod_joins_one_group() {
        // A solid rod along x: everything around it is exterior, so cutting it is allowed (it
        // removes a handle or separates two parts), unlike cutting a wall.
        assert_eq!(exterior_groups(mask(|o| o[1] != 0 || o[2] != 0)), 1);
    }

    #[test]
    fn a_simple_voxel_moves_the_boundary_and_nothing_else() {
        // Under a flat exterior, with solid below: simple.
        assert!(is_simple(mask(|o| o[2] == 1)));
        // In a wall between two exterior layers: opening it cuts a tunnel.
        assert!(!is_simple(mask(|o| o[2] != 0)));
        // The middle of a thin rod: opening it breaks the rod in two.
        assert!(!is_simple(mask(|o| o[1] != 0 || o[2] != 0)));
        // Buried: opening it starts a cavity.
        assert!(!is_simple(0));
        // Alone in the exterior: opening it only drops itself.
        assert!(is_simple((1 << 26) - 1));
    }

    #[test]
    fn exterior_groups_connect_only_through_faces() {
        // Exterior face neighbours above and below, not connected inside N18: two groups.
        assert_eq!(
            exterior_groups(mask(|o| o == [0, 0, 1] || o == [0, 0, -1])),
            2
        );
        // Joined through an edge neighbour (0, 1, 1)–(0, 1, 0)–(0, 1, -1): one group.
        assert_eq!(
            exterior_groups(mask(|o| o[0] == 0 && o[1] >= 0 && o != [0, 0, 0])),
            1
        );
    }
}
