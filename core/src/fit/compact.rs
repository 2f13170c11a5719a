//! Renumbering of vertices after the clean-up removed some (collapsed vertices no face uses):
//! every per-vertex array and every vertex index is mapped through one table.

/// Old → new vertex index (identity when nothing was removed).
pub struct Renumber {
    map: Option<Vec<u32>>,
}

impl Renumber {
    /// `removed` must be vertices no live face uses.
    pub fn new(nv: usize, removed: &[u32]) -> Renumber {
        if removed.is_empty() {
            return Renumber { map: None };
        }
        let mut gone = vec![false; nv];
        for &v in removed {
            gone[v as usize] = true;
        }
        let mut next = 0u32;
        let map = gone
            .iter()
            .map(|&g| {
                if g {
                    u32::MAX
                } else {
                    next += 1;
                    next - 1
                }
            })
            .collect();
        Renumber { map: Some(map) }
    }

    pub fn index(&self, v: u32) -> u32 {
        self.map.as_ref().map_or(v, |m| m[v as usize])
    }

    pub fn tri(&self, t: [u32; 3]) -> [u32; 3] {
        t.map(|v| self.index(v))
    }

    /// Maps indices in place (they must not be removed vertices).
    pub fn apply(&self, idx: &mut [u32]) {
        if self.map.is_some() {
            for v in idx {
                *v = self.index(*v);
            }
        }
    }

    /// The entries of a per-vertex array for the kept vertices, in order.
    pub fn vec<T: Clone>(&self, per_vertex: &[T]) -> Vec<T> {
        match &self.map {
            None => per_vertex.to_vec(),
            Some(m) => {
                per_vertex.iter().zip(m).filter(|(_, &i)| i != u32::MAX).map(|(x, _)| x.clone()).collect()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Renumber;

    #[test]
    fn removed_vertices_leave_a_dense_numbering() {
        let r = Renumber::new(5, &[1, 3]);
        assert_eq!(r.tri([0, 2, 4]), [0, 1, 2]);
        assert_eq!(r.vec(&['a', 'b', 'c', 'd', 'e']), vec!['a', 'c', 'e']);
        let id = Renumber::new(3, &[]);
        assert_eq!(id.tri([2, 1, 0]), [2, 1, 0]);
    }
}
