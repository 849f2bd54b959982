//! The floor everything stands on: reading input files safely (regular files of bounded size,
//! memory-mapped where that is faster) and writing outputs atomically ([`output`]).

pub mod huge_pages;
pub mod input;
pub mod mapped_file;
pub mod output;
