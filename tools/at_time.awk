# The relMSE and spp of a --log CSV (sampler,pass,spp,seconds,relmse,mse) at exactly T seconds: a --time render's
# last pass, cut to the time left, ends just past T, so both are interpolated between the last pass before T and
# the first at or after it (log-log for the error); without a pass at or after T (an interrupted render, or one whose
# machine sped up during its last pass), the last pass's. Prints "relmse spp". Use: awk -F, -v T=10 -f tools/at_time.awk F
$1 != "sampler" {
  if ($4 + 0 < T + 0) { t1 = $4; e1 = $5; s1 = $3; next }
  if (!done) { t2 = $4; e2 = $5; s2 = $3; done = 1 }
}
END {
  if (!done || t1 <= 0) { printf "%s %s\n", (done ? e2 : e1), (done ? s2 : s1); exit }
  f = (log(T) - log(t1)) / (log(t2) - log(t1));
  printf "%.6g %d\n", exp(log(e1) + f * (log(e2) - log(e1))), s1 + (T - t1) / (t2 - t1) * (s2 - s1) + 0.5
}
