//! Subcommands about files and databases: `info`, `convert` and `db`.

pub mod convert;
pub mod db;
pub mod info;
