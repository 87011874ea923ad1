"""The benchmarks, by family: accuracy/, peers/, speed/, galleries/, studies/; lib/ is what they share."""
