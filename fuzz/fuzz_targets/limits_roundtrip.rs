//! Limit tables: a table that parses writes back (`to_csv`) to text that
//! parses to the same table with the same hash.
#![no_main]
use acm_workbench::limits::LimitTable;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(table) = LimitTable::parse(text, "l.csv") {
        let back =
            LimitTable::parse(&table.to_csv(), "again.csv").expect("a written table reads back");
        assert_eq!(back.rows, table.rows);
        assert_eq!(back.hash(), table.hash());
    }
});
