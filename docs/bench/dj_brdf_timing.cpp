// The paper's code side by side with Facet's fit: times dj_brdf's power-iteration fit
// (Dupuy et al. 2015, https://github.com/jdupuy/dj_brdf, public domain; its
// examples/merl_params.cpp does the same calls) on MERL files, median of REPEATS runs each:
// loading the file (djb::merl), the tabulated model at N = 90 (djb::tabular: the power
// iteration and the Fresnel curve) and the moments' GGX and Beckmann α
// (fit_ggx_parameters / fit_beckmann_parameters). One thread; dj_brdf has no parallel loops.
//
//   git clone https://github.com/jdupuy/dj_brdf && cp docs/bench/dj_brdf_timing.cpp dj_brdf/
//   g++ -O3 -march=native -I dj_brdf dj_brdf/dj_brdf_timing.cpp -o dj_brdf_timing
//   ./dj_brdf_timing 5 target/fit-timing/*.binary
//
// The files are fit_timing's (`cargo run --release -p facet-fit --example fit_timing --
// target/fit-timing 5` writes and times them; SINGLE_LOBE=1 for the paper's pipeline).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>
// dj_brdf logs its steps to stdout by default.
#define DJB_LOG(format, ...) ((void)0)
#define DJ_BRDF_IMPLEMENTATION 1
#include "dj_brdf.h"

static double now_ms()
{
	using namespace std::chrono;
	return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

static double median(std::vector<double> v)
{
	std::sort(v.begin(), v.end());
	return v[v.size() / 2];
}

int main(int argc, char **argv)
{
	if (argc < 3) {
		printf("usage: %s REPEATS FILE.binary...\n", argv[0]);
		return EXIT_FAILURE;
	}
	int repeats = atoi(argv[1]);
	printf("%-40s %8s %8s %8s %8s %8s %8s\n", "file", "load", "tabular", "moments", "total",
	       "ggx α", "beck α");
	for (int i = 2; i < argc; ++i) {
		std::vector<double> load, tabular, moments;
		float ggx = 0, beckmann = 0, unused;
		for (int r = 0; r < repeats; ++r) {
			double t0 = now_ms();
			djb::merl merl(argv[i]);
			double t1 = now_ms();
			djb::tabular tab(merl, 90);
			double t2 = now_ms();
			djb::microfacet::params b = djb::tabular::fit_beckmann_parameters(tab);
			djb::microfacet::params g = djb::tabular::fit_ggx_parameters(tab);
			double t3 = now_ms();
			b.get_ellipse(&beckmann, &unused, NULL);
			g.get_ellipse(&ggx, &unused, NULL);
			load.push_back(t1 - t0);
			tabular.push_back(t2 - t1);
			moments.push_back(t3 - t2);
		}
		double l = median(load), t = median(tabular), m = median(moments);
		printf("%-40s %8.1f %8.1f %8.2f %8.1f %8.4f %8.4f\n", argv[i], l, t, m, l + t + m, ggx,
		       beckmann);
	}
	return EXIT_SUCCESS;
}
