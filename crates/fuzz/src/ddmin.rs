//! Delta debugging (Zeller and Hildebrandt, "Simplifying and Isolating Failure-Inducing
//! Input", 2002, algorithm ddmin): the smallest part of an input that still fails, tried in
//! halves, quarters, … and finally one element at a time, within a budget of runs.

/// The smallest subsequence of `items` for which `fails` holds (1-minimal when the budget
/// allows: removing any single element makes it pass). `fails(items)` is assumed true and
/// is not run; every call of `fails` takes one from `budget`, and the best so far is
/// returned when the budget runs out. Never calls `fails` with an empty slice.
pub(crate) fn ddmin<T: Clone>(
    items: Vec<T>,
    budget: &mut u64,
    fails: &mut dyn FnMut(&[T]) -> bool,
) -> Vec<T> {
    let mut cur = items;
    let mut n = 2usize;
    while cur.len() >= 2 {
        let len = cur.len();
        let n_now = n.min(len);
        let bounds: Vec<(usize, usize)> = (0..n_now)
            .map(|i| (i * len / n_now, (i + 1) * len / n_now))
            .filter(|(a, b)| a < b)
            .collect();
        let mut next: Option<(Vec<T>, usize)> = None;
        // A chunk alone.
        for (a, b) in &bounds {
            if *budget == 0 {
                return cur;
            }
            let part: Vec<T> = cur.get(*a..*b).map(<[T]>::to_vec).unwrap_or_default();
            *budget -= 1;
            if fails(&part) {
                next = Some((part, 2));
                break;
            }
        }
        // Everything but a chunk (for two chunks, the same as a chunk alone).
        if next.is_none() && n_now > 2 {
            for (a, b) in &bounds {
                if *budget == 0 {
                    return cur;
                }
                let rest: Vec<T> = cur
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| !(*a..*b).contains(i))
                    .map(|(_, x)| x.clone())
                    .collect();
                *budget -= 1;
                if fails(&rest) {
                    next = Some((rest, n_now.saturating_sub(1).max(2)));
                    break;
                }
            }
        }
        match next {
            Some((smaller, granularity)) => {
                cur = smaller;
                n = granularity;
            }
            None if n_now >= len => break,
            None => n = (n_now * 2).min(len),
        }
    }
    cur
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimal_pair_and_respects_the_budget() {
        let input: Vec<u32> = (0..40).collect();
        let mut budget = 1000;
        let mut runs = 0;
        let out = ddmin(input.clone(), &mut budget, &mut |s| {
            runs += 1;
            s.contains(&7) && s.contains(&31)
        });
        assert_eq!(out, vec![7, 31]);
        assert_eq!(1000 - budget, runs);
        assert!(runs < 120, "{runs}");

        let mut budget = 3;
        let out = ddmin(input.clone(), &mut budget, &mut |s| s.contains(&7));
        assert_eq!(budget, 0);
        assert!(out.contains(&7) && out.len() < input.len());

        let mut budget = 100;
        assert_eq!(
            ddmin(vec![1u8], &mut budget, &mut |_| unreachable!()),
            vec![1]
        );
        let mut budget = 100;
        let out = ddmin(input, &mut budget, &mut |s| {
            assert!(!s.is_empty());
            s.len() >= 3
        });
        assert_eq!(out.len(), 3);
    }
}
