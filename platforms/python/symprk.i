/* SWIG interface of the openmm_symprk native plugin (needs SWIG >= 4.4, like the openmm wheel's own). */
%module(package="openmm_symprk.plugin") symprk_swig

%import(module="openmm") "swig/OpenMMSwigHeaders.i"
%include "swig/typemaps.i"
%include "std_string.i"
%include "std_vector.i"

namespace std {
  %template(vectori) vector<int>;
  %template(vectord) vector<double>;
  %template(vectorstring) vector<string>;
};

%{
#include "OpenMM.h"
#include "OpenMMAmoeba.h"
#include "OpenMMDrude.h"
#include "openmm/RPMDIntegrator.h"
#include "openmm/RPMDMonteCarloBarostat.h"
#include "openmm/SymPRKIntegrator.h"
#include <exception>
#include <string>

/* Raise openmm.OpenMMException (what the openmm module raises) with the C++ message. */
static void symprk_set_python_error(const char* what) {
    PyObject* mod = PyImport_ImportModule("openmm");
    PyObject* cls = (mod == NULL ? NULL : PyObject_GetAttrString(mod, "OpenMMException"));
    if (cls == NULL) {
        PyErr_Clear();
        PyErr_SetString(PyExc_RuntimeError, what);
    }
    else
        PyErr_SetString(cls, what);
    Py_XDECREF(cls);
    Py_XDECREF(mod);
}
%}

%exception {
    try {
        $action
    }
    catch (std::exception& e) {
        symprk_set_python_error(e.what());
        SWIG_fail;
    }
}

/* step() releases the GIL (a PythonForce re-acquires it for its callback). */
%exception SymPRKPlugin::SymPRKIntegrator::step {
    std::string symprk_error;
    bool symprk_failed = false;
    Py_BEGIN_ALLOW_THREADS
    try {
        $action
    }
    catch (std::exception& e) {
        symprk_failed = true;
        symprk_error = e.what();
    }
    Py_END_ALLOW_THREADS
    if (symprk_failed) {
        symprk_set_python_error(symprk_error.c_str());
        SWIG_fail;
    }
}

namespace SymPRKPlugin {

class SymPRKIntegrator : public OpenMM::Integrator {
public:
    /* the same names and numbers as openmm_symprk.methods.resolved.SubstepKind and SubstepFlag */
    enum SubstepKind {
        Kick = 0,
        Drift = 1,
        Thermostat = 2
    };
    enum SubstepFlag {
        ProjectVelocitiesBefore = 1,
        ForcesCached = 2,
        FirstOfInterval = 4,
        LastOfInterval = 8
    };
    explicit SymPRKIntegrator(double stepSize);
    SymPRKIntegrator(double stepSize, const std::vector<int>& kinds, const std::vector<double>& coefficients,
                     const std::vector<int>& groups, const std::vector<int>& flags);
    void setSubsteps(const std::vector<int>& kinds, const std::vector<double>& coefficients, const std::vector<int>& groups,
                     const std::vector<int>& flags);
    int getSubstepForceGroups(int index) const;
    int getNumSubsteps() const;
    int getSubstepKind(int index) const;
    double getSubstepCoefficient(int index) const;
    int getSubstepFlags(int index) const;
    int getForceEvaluationsPerStep() const;
    bool getExactMomentum() const;
    void setExactMomentum(bool exact);
    const std::string& getMethodName() const;
    void setMethodName(const std::string& name);
    long long getStepsTaken() const;
    long long getBlowUpStep() const;
    void clearBlowUp();
    double getMaxSpeed() const;
    void setMaxSpeed(double speed);
    void setExpectedSystem(int numParticles, bool constraints);
    int getExpectedNumParticles() const;
    bool getExpectedConstraints() const;
    long long getProgramSignature() const;
    void setThermostat(double temperature, double collisionTime, long long interval, int dof, bool keepRotation);
    bool hasThermostat() const;
    double getThermostatTemperature() const;
    void setThermostatTemperature(double temperature);
    double getCollisionTime() const;
    int getThermostatInterval() const;
    int getThermostatDof() const;
    bool getThermostatKeepsRotation() const;
    int getRandomNumberSeed() const;
    void setRandomNumberSeed(int seed);
    double getHeatBathEnergy() const;
    double getThermostatKineticEnergy() const;
    double getThermostatPeculiarKineticEnergy() const;
    long long getSkippedThermostatEvents() const;
    bool getLastThermostatEventSkipped() const;
    long long getHostTransfers() const;
    long long getKernelLaunches() const;
    enum KernelFusion {
        FuseNone = 0,
        FuseSegments = 1,
        FuseAll = 2
    };
    void setKernelFusion(int mode);
    int getKernelFusion() const;
    static int getKernelFusionBlockAtoms();
    std::vector<double> sampleThermostatNoise(int count);
    static std::vector<double> computeRescalingFactor(double kinetic, double target, int dof, double c, double r1, double chi2);
    static void registerMissingKernelFactories();
    void step(int steps);
    /* for tests: the step plan of the bound Context and what the kernel executed of it */
    std::vector<std::string> getStepPlan() const;
    void setExecutionTraceEnabled(bool record);
    std::vector<int> getExecutionTrace() const;
    %extend {
        /** The same integrator seen as a SymPRKIntegrator (e.g. after XmlSerializer.deserialize). */
        static SymPRKPlugin::SymPRKIntegrator& cast(OpenMM::Integrator& integrator) {
            SymPRKPlugin::SymPRKIntegrator* p = dynamic_cast<SymPRKPlugin::SymPRKIntegrator*>(&integrator);
            if (p == NULL)
                throw OpenMM::OpenMMException("the integrator is not a SymPRKIntegrator");
            return *p;
        }
        static bool isinstance(OpenMM::Integrator& integrator) {
            return dynamic_cast<SymPRKPlugin::SymPRKIntegrator*>(&integrator) != NULL;
        }
    }
};

}
