//! Names of the drill pipe's parts: the one place they are formatted.
//!
//! Names appear in outputs (the `body` and `pair` columns) and in error
//! messages, for people. Programs use the ids of the tables (`link`,
//! `hinge`, `key`; the `bodies` table's `part` and the `pairs` table's
//! `feature`) or the [`Layout`](super::Layout) instead; nothing parses these
//! names back.

/// The fixed guide tube.
pub const TUBE: &str = "tube";
/// The driven upper connector.
pub const UPPER: &str = "upper";
/// The lower connector, loaded by the resisting moment.
pub const LOWER: &str = "lower";

/// Body in chain position `k`: 0 the upper connector, 1…n the links, n + 1 the lower connector.
pub fn chain_body(k: usize, links: usize) -> String {
    match k {
        0 => UPPER.to_string(),
        k if k > links => LOWER.to_string(),
        k => format!("link{k:02}"),
    }
}

/// Link `k`'s contact with the tube.
pub fn tube_pair(link: usize) -> String {
    format!("{}/{TUBE}", chain_body(link, usize::MAX))
}

/// Hinge `h` (the ideal-CV joint's name, and the prefix of its parts).
pub fn hinge(h: usize) -> String {
    format!("h{h:02}")
}

/// The neck–mouth contact (articulation limit) of hinge `h`.
pub fn neck(h: usize) -> String {
    format!("{}.neck", hinge(h))
}

/// The cage of hinge `h`.
pub fn cage(h: usize) -> String {
    format!("{}.cage", hinge(h))
}

/// Ball key `j` of hinge `h`.
pub fn key(h: usize, j: usize) -> String {
    format!("{}.key{j}", hinge(h))
}

/// A contact feature `feature` (e.g. `head+`, `window-side`) of a part.
pub fn feature(part: &str, feature: &str) -> String {
    format!("{part}/{feature}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_positions_name_connectors_and_links() {
        assert_eq!(chain_body(0, 12), "upper");
        assert_eq!(chain_body(3, 12), "link03");
        assert_eq!(chain_body(13, 12), "lower");
        assert_eq!(tube_pair(10), "link10/tube");
        assert_eq!(feature(&key(2, 4), "head+"), "h02.key4/head+");
    }
}
